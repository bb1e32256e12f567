// Weighted least squares shared by the acceptance analyses (acceptance.hpp).
#include "compensation/acceptance.hpp"

#include <cmath>

namespace station::compensation {

Computed<WeightedFit> weighted_least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                             const Eigen::VectorXd& se) {
  const Eigen::Index n = x.rows(), p = x.cols();
  if (n < p)
    return NotComputed{std::to_string(n) + " points for " + std::to_string(p) + " unknowns"};
  // Rows weighted by 1/se (Seber & Lee, Linear Regression Analysis, 2nd ed., section 3.10:
  // generalized least squares with a diagonal covariance), columns scaled to unit norm so the
  // QR's rank test and the triangular solve see a well-scaled matrix.
  const Eigen::VectorXd w = se.cwiseInverse();
  Eigen::MatrixXd xw = w.asDiagonal() * x;
  const Eigen::VectorXd yw = w.cwiseProduct(y);
  Eigen::VectorXd col_norm(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    col_norm(j) = xw.col(j).norm();
    if (!(col_norm(j) > 0)) return NotComputed{"a column of the design is all zero"};
    xw.col(j) /= col_norm(j);
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(xw);
  const Eigen::MatrixXd r = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  const double r_max = r.diagonal().cwiseAbs().maxCoeff();
  if (!(r.diagonal().cwiseAbs().minCoeff() > 1e-12 * r_max))
    return NotComputed{"the design's columns are linearly dependent (too few distinct points)"};
  WeightedFit fit;
  const Eigen::VectorXd b_scaled = qr.solve(yw);
  fit.coefficients = b_scaled.cwiseQuotient(col_norm);
  // (X'WX)^-1 = D^-1 R^-1 R^-T D^-1 for the scaled factor Xs = Q R, D = diag(col_norm).
  const Eigen::MatrixXd r_inv =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::VectorXd d_inv = col_norm.cwiseInverse();
  fit.covariance = d_inv.asDiagonal() * (r_inv * r_inv.transpose()) * d_inv.asDiagonal();
  fit.residuals = y - x * fit.coefficients;
  fit.chi2 = w.cwiseProduct(fit.residuals).squaredNorm();
  fit.dof = static_cast<std::size_t>(n - p);
  // The PDG rule (acceptance.hpp): inflate by chi2/dof only when it exceeds 1.
  if (fit.dof > 0 && fit.chi2 / fit.dof > 1.0) {
    fit.covariance *= fit.chi2 / fit.dof;
    fit.se_scale = std::sqrt(fit.chi2 / fit.dof);
  }
  return fit;
}

Computed<WeightedFit> ordinary_least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                             const Eigen::VectorXd& se) {
  // Equal weights: the same QR with se = 1 gives b and (X'X)^-1 (its chi2/dof rule undone).
  const auto ols = weighted_least_squares(x, y, Eigen::VectorXd::Ones(y.size()));
  if (!ols) return ols;
  WeightedFit fit = *ols;
  const Eigen::MatrixXd xtx_inv = fit.covariance / (fit.se_scale * fit.se_scale);
  const Eigen::MatrixXd l = xtx_inv * x.transpose();  // b = L y
  fit.covariance = l * se.cwiseAbs2().asDiagonal() * l.transpose();
  fit.chi2 = fit.residuals.cwiseQuotient(se).squaredNorm();
  fit.se_scale = 1;
  return fit;
}

double delta_method_variance(const Eigen::VectorXd& grad, const Eigen::MatrixXd& covariance) {
  return grad.dot(covariance * grad);
}

double wrap_deg(double angle_deg) {
  double a = std::fmod(angle_deg, 360.0);
  if (a <= -180.0) a += 360.0;
  if (a > 180.0) a -= 360.0;
  return a;
}

}  // namespace station::compensation
