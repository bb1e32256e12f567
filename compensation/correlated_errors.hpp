// Honest standard errors for least squares over bins whose noise is correlated in time.
//
// A gyro's 600 s bins share bias-instability noise whose correlation time is near an hour, so
// the iid OLS formula s^2 (X'X)^-1 is optimistic. The bin errors are modelled as white noise plus
// a first-order Gauss-Markov process (IEEE Std 952-1997, Annex C: "correlated noise"; the
// simulator's bias instability is the same process), i.e. an AR(1)-plus-white-noise process on
// the bin times:  Cov(e_i, e_j) = s^2 [ (1 - q) d_ij + q exp(-|t_i - t_j| / tau) ].
// Its parameters (tau, q) are estimated by restricted maximum likelihood (REML: Patterson &
// Thompson 1971; Harville 1977, JASA 72:320), evaluated in O(n p) by a scalar Kalman filter with
// the regression coefficients concentrated out (Harvey, "Forecasting, structural time series
// models and the Kalman filter", 1989, sec. 3.4 and 5.2). The coefficients stay the ordinary
// least-squares ones (the paper's method); their covariance under the fitted error model is the
// sandwich  s^2 (X'X)^-1 X' R X (X'X)^-1  (e.g. Greene, Econometric Analysis, 7th ed., eq. 9-9).
// Pure maths: no I/O.
#pragma once

#include <Eigen/Dense>
#include <span>
#include <string>

namespace station::compensation {

/// The fitted error model of a regression's bins.
struct ErrorModel {
  std::string method = "iid";   ///< "ar1+white (REML)" or "iid" (too few bins to estimate)
  double corr_time_s = 0;       ///< tau of the Gauss-Markov part, s (0: none)
  double correlated_share = 0;  ///< q: share of the error variance in the Gauss-Markov part
  double sigma_dph = 0;         ///< s: total error standard deviation per bin, deg/h
  double rho_per_bin = 0;       ///< exp(-bin spacing / tau): correlation of neighbouring bins
  /// The estimate sits on the edge of what the search allows (q = 0.99 or tau ten record
  /// lengths): the bins look like a drift more than noise, and the errors are less certain.
  bool on_search_boundary = false;
};

/// Estimates the error model of y = X b + e by REML. `x` should be well conditioned (pass the
/// orthonormal Q of X = Q R: the likelihood depends only on the column space of X). `t_s` are the
/// bin times (increasing within a segment), `segment` the run each bin came from (bins of different
/// runs are independent; empty: one run). Needs at least p + 4 bins; with fewer the model is "iid"
/// with s^2 = RSS/(n-p).
ErrorModel estimate_error_model(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                std::span<const double> t_s, std::span<const int> segment);

/// Variances of the OLS coefficients of y = X b + e under `model`, with X = Q R (thin QR,
/// Q `q_basis` n x p, `r_inv` = R^-1): the diagonal of s^2 R^-1 Q' C Q R^-T, O(n p).
Eigen::VectorXd ols_variances_under(const ErrorModel& model, const Eigen::MatrixXd& q_basis,
                                    const Eigen::MatrixXd& r_inv, std::span<const double> t_s,
                                    std::span<const int> segment);

}  // namespace station::compensation
