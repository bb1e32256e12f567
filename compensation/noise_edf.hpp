// The equivalent degrees of freedom of a deviation estimated under the power-law noise that
// dominates at its averaging time (noise_id.hpp says which): what an honest confidence interval
// of ADEV or HDEV needs. alpha is the exponent of the rate's power spectral density
// S(f) ~ f^alpha: +2 white PM, +1 flicker PM, 0 white FM (angle random walk), -1 flicker FM
// (bias instability), -2 random-walk FM (rate random walk).
//
// EDF: Greenhall & Riley, "Uncertainty of stability variances based on finite differences",
// Proc. 35th PTTI (2003), eqs. (7)-(13) and Tables 1-3 (NIST SP 1065 §5.3 cites it as the
// general method): exact sums over the estimator's autocovariance for short sums, the tables'
// asymptotic forms for long ones.
#pragma once

namespace station::compensation {

/// Equivalent degrees of freedom (Greenhall & Riley 2003) of a d-th difference variance
/// (d = 2 Allan, 3 Hadamard) at averaging factor m from n_phase phase (angle) points, for
/// power-law exponent alpha (requires alpha + 2 d > 1), overlapping (stride 1) or not.
double greenhall_edf(int alpha, int d, double m, double n_phase, bool overlapping);

}  // namespace station::compensation
