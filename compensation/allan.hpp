// Allan deviation of a rate series and the noise terms read off its curve.
// IEEE Std 952-1997 Annex C (and IEEE Std 647), NIST SP 1065 (Riley 2008) §5.2.4, §5.3.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "compensation/noise_id.hpp"

namespace station::compensation {

/// How averaging factors m (tau = m * tau0) are chosen.
enum class TauSpacing { octave, decade, all };

/// Parses "octave", "decade" or "all"; empty for anything else.
std::optional<TauSpacing> tau_spacing_from_name(std::string_view name);

/// Averaging factors for a series of n rate samples: octave 1,2,4,...; decade 1,2,4 x 10^k;
/// all 1..; each m kept while the overlapping estimator still has at least 2 terms (n - 2m + 1 >=
/// 2).
std::vector<std::size_t> tau_factors(std::size_t n, TauSpacing spacing);

/// One point of an Allan deviation curve.
struct AdevPoint {
  double tau_s = 0;    ///< averaging time m * tau0, seconds
  std::size_t m = 0;   ///< averaging factor
  double adev = 0;     ///< overlapping Allan deviation, in the input's rate unit
  double ci_low = 0;   ///< lower bound of the confidence interval (same unit)
  double ci_high = 0;  ///< upper bound
  std::size_t n = 0;   ///< number of terms in the overlapping sum (N - 2m, N angle points)
  double edf = 0;      ///< equivalent degrees of freedom used for the interval
  /// Power-law exponent of the noise the interval assumes (noise_id.hpp: +2 white PM .. -2
  /// random-walk FM), identified at this tau (`noise_id` says how) or, with fewer than
  /// kMinB1Averages averages left, carried from the largest tau where it was (white FM when none).
  int alpha = 0;
  /// How alpha was found: lag-1 autocorrelation (30 averages or more), B1 ratio (8 to 29) or
  /// none (carried).
  NoiseIdMethod noise_id = NoiseIdMethod::none;
};

/// Which deviation: Allan (second difference of the angle) or Hadamard (third difference:
/// insensitive to a linear drift of the rate; NIST SP 1065 §5.2.8).
enum class DeviationKind { adev, hdev };

/// The integrated angle of `rate` in units of (rate unit) x (sample interval), its mean rate
/// removed: theta_0 = 0, theta_k = sum_{i<k} (y_i - mean), M + 1 points for M samples (the phase
/// x = tau0 theta of NIST SP 1065 §5.2). What every deviation is a difference of. Pure.
std::vector<double> integrated_angle(std::span<const double> rate);

/// Overlapping ADEV (or HDEV) of `rate` (any rate unit, sampled at rate_hz) at each factor in
/// `m_list` (increasing), computed from the integrated angle in one tiled sweep for all taus
/// (vector_sums.hpp: O(N) work per tau, the angle read from memory a few times in all); interval
/// at `confidence` (two-sided) from the chi-squared distribution with the equivalent degrees of
/// freedom of Greenhall & Riley for the noise identified at that tau in its tau-averaged series
/// (noise_id.hpp, BlockAverages: each formed from the previous tau's, one pass in all). Factors
/// with fewer than 1 term are skipped. Throws DataError unless rate_hz > 0 is finite,
/// 0 < confidence < 1 and every sample is finite, or when the result overflows. Pure but for
/// its working memory (12 bytes a sample), which the calling thread keeps for its next curve.
std::vector<AdevPoint> overlapping_adev(std::span<const double> rate, double rate_hz,
                                        std::span<const std::size_t> m_list,
                                        double confidence = 0.683,
                                        DeviationKind kind = DeviationKind::adev);

/// The two-sided interval of a deviation `dev` estimated with `edf` equivalent degrees of
/// freedom at `confidence`: edf s^2 / sigma^2 ~ chi^2(edf) (NIST SP 1065 §5.3, eq. 47).
std::pair<double, double> chi_squared_interval(double dev, double edf, double confidence);

/// Noise coefficients read off an ADEV curve of a rate series in deg/h (IEEE 952 Table C.2).
/// Each is empty when the curve does not reach the region it is read from.
struct NoiseTerms {
  std::optional<double> quantization_arcsec;        ///< Q: tau^-1 line, sigma = sqrt(3) Q / tau
  std::optional<double> angle_random_walk_deg_rth;  ///< N: tau^-1/2 line at tau = 1 s, deg/sqrt(h)
  std::optional<double> bias_instability_dph;       ///< B: flat minimum / 0.664, deg/h
  std::optional<double> bias_instability_tau_s;     ///< tau of that minimum, s
  std::optional<double> rate_random_walk_dph_rth;   ///< K: tau^+1/2 line at tau = 3, deg/h/sqrt(h)
  /// Standard errors of the four, when they come from the weighted fit (fit_noise_terms).
  std::optional<double> quantization_se, angle_random_walk_se, bias_instability_se,
      rate_random_walk_se;
  /// The fit's chi^2 per degree of freedom (about 1 when the four terms explain the curve).
  std::optional<double> fit_chi2_per_dof;
};

/// The IEEE 952 terms from a weighted least-squares fit of the Allan variance over the whole
/// curve (IEEE Std 952-1997 Annex C, Table C.2: sigma^2 = 3 Q^2/tau^2 + N'^2/tau + (2 ln 2/pi) B^2
/// + K'^2 tau/3), each point weighted by the inverse variance of its AVAR estimate,
/// 2 sigma^4 / edf (chi-squared with the point's Greenhall edf), the model's sigma iterated in
/// place of the noisy estimate; the squared coefficients kept non-negative (the best of the
/// term subsets whose fit is feasible: the NNLS solution). At most 4 points per octave enter
/// (denser curves are thinned by tau). The terms do not depend on which taus the curve has.
/// Standard errors: the sandwich covariance of that fit under the model covariance of the
/// correlated overlapping AVAR estimates at the fitted terms (noise_fit_cov.hpp; points without
/// m and n, e.g. an analytic curve, are taken as independent with variance 2 sigma^4 / edf),
/// scaled up by fit_chi2_per_dof when that is above 1, and carried to each coefficient by the
/// delta method (se(c) = se(c^2) / 2c). fit_chi2_per_dof is the generalized chi^2 of the
/// residuals under that covariance over its expectation (about 1 when the terms explain the
/// curve; chi^2 / dof for independent points). Q is reported only when Q^2 is above 0 at the
/// one-sided 1 % level under that covariance, else the other terms are refit without it (1 to
/// 3 % of Q-free records report one in test NoiseFitCoverage); N, B and K whenever the fit keeps
/// them. Rate in deg/h, tau in s. A few ms for an octave curve of 2e6 samples. Pure.
NoiseTerms fit_noise_terms(std::span<const AdevPoint> curve);

/// The Allan deviation the terms predict at tau (deg/h): the fitted model drawn on a figure.
double noise_model_adev(const NoiseTerms& terms, double tau_s);

/// Reads the noise terms off `curve` (rate in deg/h, tau in s): each coefficient from the tangent
/// line of its slope touching the curve from below, only where the curve has a stretch of that
/// slope (+-0.25). Points with 0 < edf < min_edf are ignored (too noisy to read); edf == 0 marks
/// an exact (e.g. analytic) point. Pure.
NoiseTerms noise_terms(std::span<const AdevPoint> curve, double min_edf = 50.0);

}  // namespace station::compensation
