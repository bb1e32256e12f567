// The part's noise as an input to the bins' error model (issue 32, point 3).
//
// One run's bins cannot tell a rate random walk thirty times an RLG's from a slightly different
// k1 (tests WalkIdentifiability; docs/UNCERTAINTY.md): what settles it is knowledge from outside
// the run, a data sheet's IEEE 952 terms or `station adev`'s term fit on a static run of the type.
// Given, each term is a log-normal prior on the matching part of the error model of
// correlated_errors.hpp, centred on the value given, with a geometric standard deviation of
// `trust_factor` (the true value within x/÷ trust_factor in 68 % of parts):
//   N (angle random walk, deg/sqrt(h))  <-> the white part's sd per bin, 60 N / sqrt(bin_s) deg/h
//                                          (IEEE Std 952-1997, C.1.2: sigma(tau) = N / sqrt(tau));
//   K (rate random walk, deg/h/sqrt(h)) <-> the model's walk, K^2 per hour of variance growth
//                                          (C.1.4), centred on K_w = sqrt(K^2 + K_B^2);
//   B (bias instability, deg/h)          -> K_B, the walk that over one run looks like the part's
//                                          flicker: equal Allan variances at the run's length T,
//                                          K_B^2 T / 3 = (2 ln 2 / pi) B^2 (C.1.3, C.1.4), so
//                                          K_B = B sqrt(6 ln 2 / (pi T)), T in hours (at T / 3
//                                          the flicker cells over-covered: 0.85 at 1 SE). The error
//                                          model has no flicker term: over one record its walk and
//                                          Gauss-Markov parts stand for it (correlated_errors.hpp),
//                                          and a part with flicker and no walk still needs them.
// K_w = 0 (K = 0 and no B) says the part has no walk at all: walks are excluded.
// The error model's point estimate and the weights of its mixture become restricted likelihood x
// prior (Bayes' rule; the search space and everything else unchanged).
// Pure maths: no I/O.
#pragma once

#include <optional>

namespace station::compensation {

/// The bounds a given noise term and trust factor must keep (the part file and `analyze` both
/// check them): a term above 1e6 in its unit, or a trust of x1.01 or less or above x1000, is a
/// typo, not a part.
inline constexpr double kMaxNoiseTerm = 1e6;
inline constexpr double kMinNoiseTrust = 1.01, kMaxNoiseTrust = 1000.0;

struct NoisePrior {
  std::optional<double> arw_deg_rt_h;          ///< N, deg/sqrt(h)
  std::optional<double> bias_instability_dph;  ///< B, deg/h
  std::optional<double> rrw_dph_rt_h;          ///< K, deg/h/sqrt(h); 0: no walk
  /// Geometric sd of the log-normal priors (> 1). At 3 the strong walks' cells stayed under the
  /// band (K 0.003: 0.60 / 0.90 at 1 / 2 SE on the paper cycle); at 2 they are in it.
  double trust_factor = 2.0;

  bool empty() const { return !arw_deg_rt_h && !rrw_dph_rt_h && !bias_instability_dph; }
};

/// -2 log of the prior density (constants dropped) at an error model whose white part has sd
/// `white_sd_dph` per bin of `bin_s` seconds and whose walk is `rrw_dph_rt_h` (0: none), over a
/// run of `span_h` hours. A walk where the part has none (K_w = 0) is +infinity; no walk where
/// the part has one is scored at K_w / trust_factor^3, three geometric sds below.
double noise_prior_penalty(const NoisePrior& prior, double white_sd_dph, double rrw_dph_rt_h,
                           double bin_s, double span_h);

/// K_w of the header over a run of span_h hours: the walk the prior is centred on,
/// deg/h/sqrt(h); empty: no prior on the walk.
std::optional<double> prior_walk_dph_rt_h(const NoisePrior& prior, double span_h);

}  // namespace station::compensation
