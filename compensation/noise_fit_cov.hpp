// The covariance of the overlapping Allan-variance estimates of one curve under the IEEE 952
// noise model: what the fit of the noise terms (fit_noise_terms, allan.hpp) needs for honest
// standard errors, since the estimates at different taus share the same data.
//
// For Gaussian noise with second differences d_{m,k} = x_{k+2m} - 2 x_{k+m} + x_k of the phase
// x (NIST SP 1065 §5.2.4, overlapping AVAR s2(m) = sum_k d_{m,k}^2 / (2 tau_m^2 M_m), M_m terms),
// Isserlis' theorem gives Cov(d^2, e^2) = 2 Cov(d, e)^2, so
//   Cov(s2(m), s2(n)) = 2 / (4 tau_m^2 tau_n^2 M_m M_n) sum_j count(j) C_mn(j)^2,
//   C_mn(j) = sum_{a,b = 0..2} c_a c_b G(tau0 (j + a m - b n)),  c = (1, -2, 1),
// count(j) the number of index pairs (k, l) with k - l = j, and G the generalized
// autocovariance of the phase (Greenhall & Riley, Proc. 35th PTTI 2003, eqs. 7-10, where the
// same sums give the edf of one estimate). G of the four terms, in (deg/h) s = arcsec:
//   white PM Q^2 at t = 0; white FM -0.5 (60 N)^2 |t|; flicker FM (B^2 / 2 pi) t^2 ln|t|;
//   random-walk FM K^2 |t|^3 / (12 * 3600),
// each giving its IEEE 952 Table C.2 AVAR: sum_ab c_a c_b G((a - b) tau) / (2 tau^2) =
// 3 Q^2/tau^2, 3600 N^2/tau, (2 ln 2/pi) B^2, K^2 tau / 10800.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <optional>
#include <span>

#include "compensation/allan.hpp"

namespace station::compensation {

/// Squared noise terms theta = (Q^2, N^2, B^2, K^2) in arcsec^2, deg^2/h, (deg/h)^2 and
/// deg^2/h^3: the AVAR is linear in them (IEEE 952 Table C.2).
using NoiseTheta = std::array<double, 4>;

/// The covariance of a curve's AVAR estimates, (deg/h)^4, as a quadratic form in theta:
/// Cov = sum_{t <= u} theta_t theta_u parts[t][u]. Built once per curve, evaluated at any theta.
class AvarCovariance {
 public:
  /// For the points of one overlapping ADEV curve (overlapping_adev): every point needs m >= 1,
  /// n >= 1 and the same tau0 = tau_s / m. Empty otherwise. Cost: ~15 us per pair of points
  /// (quadrature over the lags, see the .cpp), 3 ms for an octave curve of 2e6 samples. Pure.
  static std::optional<AvarCovariance> of(std::span<const AdevPoint> pts);

  /// The covariance matrix of the points' AVAR estimates at theta, (deg/h)^4. Pure.
  Eigen::MatrixXd at(const NoiseTheta& theta) const;

 private:
  std::array<std::array<Eigen::MatrixXd, 4>, 4> parts_;  // [t][u] used for t <= u
};

}  // namespace station::compensation
