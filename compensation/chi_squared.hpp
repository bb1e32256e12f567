// Chi-squared distribution quantiles, for Allan-deviation confidence intervals (NIST SP 1065 §5.3).
#pragma once

namespace station::compensation {

/// Regularized lower incomplete gamma P(a, x), a > 0, x >= 0 (A&S 6.5.29 series / 6.5.31
/// continued fraction); throws std::domain_error outside that domain.
double regularized_gamma_p(double a, double x);

/// The p-quantile of the chi-squared distribution with `dof` (> 0, may be fractional) degrees of
/// freedom: the x with P(dof/2, x/2) = p. Accurate to ~1e-10 relative; throws std::domain_error
/// for p outside [0, 1] or dof <= 0.
double chi_squared_quantile(double p, double dof);

}  // namespace station::compensation
