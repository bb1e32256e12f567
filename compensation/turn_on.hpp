// Turn-on repeatability and warm-up of a gyro powered up N times (issue 36, power_cycles).
// Pure maths: per turn-on a series of bins (time since power-on, bias) in, figures out.
//
// Definitions (each turn-on k has bins (t_j, b_j), t_j strictly increasing, t = 0 at power-on):
//   Turn-on bias:  b_k = mean of the b_j with bias_start_s <= t_j <= bias_end_s (a window the
//     caller places after warm-up); its SE = sample std of those bins / sqrt(their number)
//     (independent bins; with correlated bins it is optimistic).
//   Final value:  f_k = mean of the b_j with final_start_s <= t_j <= final_end_s.
//   Warm-up time:  with d_j = b_j - f_k and L the last bin with |d_j| > band_dph, the bias
//     stays within the band from the crossing between bins L and L+1 on to the end of the
//     series. The crossing is interpolated on ln|d| when d_L and d_{L+1} have the same sign and
//     d_{L+1} != 0 (exact for an exponential settling b = f + A e^(-t/tau): it gives
//     t = tau ln(A / band)), else linearly on d towards sign(d_L) * band. No bin outside the
//     band: the warm-up is t_0 (the first bin; the data cannot show an earlier settling).
//     The last bin outside the band: not settled (empty).
//   Repeatability:  s = sample std (N - 1 in the denominator) of the N turn-on biases b_k:
//     the turn-on-to-turn-on spread, sigma. It includes each b_k's own window noise (SE^2 on
//     average); mean_bias_se_dph is reported beside it so a reader can see that share.
//     Confidence interval for sigma at level c from (N-1) s^2 / sigma^2 ~ chi^2(N-1) for
//     normal b_k: [s sqrt((N-1)/q_hi), s sqrt((N-1)/q_lo)], q_hi, q_lo the (1+c)/2 and (1-c)/2
//     quantiles of chi^2(N-1) (NIST/SEMATECH e-Handbook of Statistical Methods, section
//     1.3.5.8, "Chi-Square Test for the Standard Deviation"; quantiles from chi_squared.hpp).
//
// Sources: turn-on time, warm-up and turn-on-to-turn-on bias repeatability are test items of
// IEEE Std 647-2006 (laser gyros) and IEEE Std 952-1997 (fibre-optic gyros) per their public
// abstracts and issue 36; the clause texts were not available, so the window and band rule
// above is this station's own, stated exactly so it can be compared with a customer's.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "compensation/acceptance.hpp"

namespace station::compensation {

/// One turn-on's bins: time since power-on, s (strictly increasing), and the bias, deg/h
/// (the output minus the Earth rate along the axis, earth_rate.hpp), the same length.
struct TurnOnSeries {
  std::span<const double> t_s;
  std::span<const double> bias_dph;
};

/// The caller's windows (inclusive, s since power-on) and band.
struct TurnOnWindows {
  double bias_start_s = 0;  ///< the turn-on bias window, after warm-up
  double bias_end_s = 0;
  double final_start_s = 0;  ///< the final-value window the warm-up band is centred on
  double final_end_s = 0;
  double band_dph = 0;       ///< half-width of the warm-up band, deg/h (> 0)
  double confidence = 0.95;  ///< level of the repeatability's interval, in (0, 1)
  /// The sd of one turn-on bias's pulse quantization, deg/h (0: none); widens the interval's
  /// upper end (turn_on_repeatability).
  double bias_quantization_dph = 0;
};

/// One turn-on's figures.
struct TurnOnFigures {
  double bias_dph = 0;     ///< mean over the bias window
  double bias_se_dph = 0;  ///< sample std of those bins / sqrt(bias_bins)
  std::size_t bias_bins = 0;
  double final_dph = 0;  ///< mean over the final window
  std::size_t final_bins = 0;
  std::optional<double> warmup_s;  ///< empty: the last bin is outside the band (not settled)
};

/// Turn-on-to-turn-on repeatability: the sample std of the turn-on biases with its interval.
struct TurnOnRepeatability {
  std::size_t turn_ons = 0;
  std::size_t dof = 0;  ///< turn_ons - 1
  double mean_bias_dph = 0;
  double repeatability_dph = 0;        ///< s
  double repeatability_lower_dph = 0;  ///< chi-square interval for sigma, lower end
  double repeatability_upper_dph = 0;  ///< upper end
  double confidence = 0.95;
};

/// All turn-ons of a power-cycle test.
struct TurnOnResult {
  std::vector<TurnOnFigures> turn_ons;  ///< in the input's order
  TurnOnRepeatability repeatability;
  double mean_bias_se_dph = 0;         ///< RMS of the turn-ons' bias_se_dph
  std::optional<double> max_warmup_s;  ///< the longest warm-up; empty when none settled
  std::size_t not_settled = 0;         ///< turn-ons with no warm-up time
};

/// The warm-up time of one series against `final_dph` (definition above); empty optional when
/// it never settles. NotComputed on an empty or malformed series or band <= 0.
Computed<std::optional<double>> warmup_time_s(const TurnOnSeries& series, double final_dph,
                                              double band_dph);

/// One turn-on's bias, final value and warm-up. NotComputed when the series is malformed (a
/// value not finite or beyond kMaxAbsRateDph, times not increasing, lengths differ), a window
/// is empty or inverted, or a window holds fewer than 2 bins.
Computed<TurnOnFigures> analyze_turn_on(const TurnOnSeries& series, const TurnOnWindows& w);

/// Repeatability of given turn-on biases. NotComputed for fewer than 2, a value not finite,
/// a confidence outside (0, 1) or a negative quantization.
///
/// Quantized biases: a counter's bias over a window is a whole number of pulses, so two
/// turn-ons can read exactly the same bias (s = 0) far more often than normal data would, and
/// the chi-square interval would then be [0, 0]. Each bias carries a rounding error of sd u =
/// `quantization_dph` (independent between turn-ons; GUM 4.3.7) that s may have hidden: the
/// upper end is computed from s_u = sqrt(s^2 + u^2) instead of s (the lower end, and s itself,
/// stay as measured). The station-level Monte Carlo (tests/station/test_acceptance_coverage.cpp)
/// measured the interval's coverage without it at 0.85 for a nominal 0.95.
Computed<TurnOnRepeatability> turn_on_repeatability(std::span<const double> biases_dph,
                                                    double confidence, double quantization_dph = 0);

/// Every turn-on, then the repeatability of their biases. NotComputed names the first turn-on
/// that could not be analyzed.
Computed<TurnOnResult> analyze_turn_ons(std::span<const TurnOnSeries> turn_ons,
                                        const TurnOnWindows& w);

}  // namespace station::compensation
