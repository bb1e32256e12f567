// The power-law noise at each averaging time and the equivalent degrees of freedom of a
// deviation estimated under it: what an honest confidence interval of ADEV or HDEV needs.
//
// Noise identification: the lag-1 autocorrelation method of Riley & Greenhall, "Power law noise
// identification using the lag 1 autocorrelation", Proc. 18th EFTF (2004) (NIST SP 1065 §5.6):
// the rate (fractional-frequency-like) series is averaged in non-overlapping blocks of m, a line
// removed, and differenced d times until delta = r1 / (1 + r1) < 0.25 (or d = d_max: 2 for the
// Allan, 3 for the Hadamard variance); then alpha = -round(2 delta) - 2 d, the exponent of the
// rate's power spectral density S(f) ~ f^alpha: +2 white PM, +1 flicker PM, 0 white FM (angle
// random walk), -1 flicker FM (bias instability), -2 random-walk FM (rate random walk).
//
// EDF: Greenhall & Riley, "Uncertainty of stability variances based on finite differences",
// Proc. 35th PTTI (2003), eqs. (7)-(13) and Tables 1-3 (NIST SP 1065 §5.3 cites it as the
// general method): exact sums over the estimator's autocovariance for short sums, the tables'
// asymptotic forms for long ones.
#pragma once

#include <cstddef>
#include <optional>
#include <span>

namespace station::compensation {

/// Points the identification needs after averaging (Riley & Greenhall: about 30).
inline constexpr std::size_t kMinNoiseIdPoints = 30;

/// What the lag-1 method found at one averaging factor.
struct NoiseId {
  int alpha = 0;         ///< integer power-law exponent of the rate's PSD, +2 .. -2
  double alpha_est = 0;  ///< the unrounded estimate -2 (delta + d)
  int differences = 0;   ///< d
};

/// Identifies the dominant power-law noise of `rate` at averaging factor m; empty when fewer than
/// kMinNoiseIdPoints averages remain. `d_max` is 2 for ADEV, 3 for HDEV. The result is clamped to
/// the range the variance converges for (alpha > 1 - 2 d_max... i.e. -2 .. +2 for ADEV).
std::optional<NoiseId> identify_noise(std::span<const double> rate, std::size_t m, int d_max);

/// Equivalent degrees of freedom (Greenhall & Riley 2003) of a d-th difference variance
/// (d = 2 Allan, 3 Hadamard) at averaging factor m from n_phase phase (angle) points, for
/// power-law exponent alpha (requires alpha + 2 d > 1), overlapping (stride 1) or not.
double greenhall_edf(int alpha, int d, double m, double n_phase, bool overlapping);

}  // namespace station::compensation
