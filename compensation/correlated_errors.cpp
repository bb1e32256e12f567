// REML estimate of an AR(1)-plus-white error model by a Kalman filter, and the OLS covariance
// under it (see the header for the method and its sources).
#include "compensation/correlated_errors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace station::compensation {
namespace {

constexpr double kMaxShare = 0.99;  // q = 1 with tau -> infinity makes the filter degenerate
constexpr int kCoarseSteps = 15;    // 15 x 15 grid over log tau and q, then
constexpr int kRefinements = 4;     // 4 rounds of 5 x 5 around the best point
// The filter's columns: y and up to 9 regressors (B0 and the eight terms of fit.hpp).
constexpr int kMaxColumns = 10;
using SmallMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxColumns, kMaxColumns>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxColumns, 1>;

bool same_run(std::span<const int> segment, Eigen::Index i, Eigen::Index j) {
  return segment.empty() ||
         segment[static_cast<std::size_t>(i)] == segment[static_cast<std::size_t>(j)];
}

double time_of(std::span<const double> t_s, Eigen::Index i) {
  return t_s.empty() ? static_cast<double>(i) : t_s[static_cast<std::size_t>(i)];
}

/// Correlation of the Gauss-Markov part from bin i-1 to bin i, for each bin (0 across runs).
void step_corrs(std::vector<double>& phi, std::span<const double> t_s, std::span<const int> segment,
                Eigen::Index n, double tau_s) {
  phi.assign(static_cast<std::size_t>(n), 0.0);
  for (Eigen::Index i = 1; i < n; ++i) {
    if (!same_run(segment, i, i - 1)) continue;
    phi[static_cast<std::size_t>(i)] =
        std::exp(-std::abs(time_of(t_s, i) - time_of(t_s, i - 1)) / tau_s);
  }
}

struct Profile {
  double minus2_loglik = std::numeric_limits<double>::infinity();
  double sigma2 = 0;
};

/// -2 x restricted log-likelihood (constants dropped) of (tau, q) with b and s^2 concentrated
/// out. The filter runs on y and on every column of X with the same gains (Harvey 1989, 3.4.2):
/// innovations v, their variances f (in units of s^2); GLS normal equations from v/sqrt(f).
/// `z` holds the rows [y_i, x_i] (n x (p+1), row-major); plain loops: it runs ~250 times a fit.
Profile reml_profile(
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& z,
    const std::vector<double>& phi, double q) {
  const Eigen::Index n = z.rows(), k = z.cols(), p = k - 1;
  // [y X]' F^-1 [y X] of the innovations; sizes bounded by kMaxColumns, so nothing is allocated.
  SmallMatrix m = SmallMatrix::Zero(k, k);
  std::array<double, kMaxColumns> state{}, v{};
  // f >= 1 - q >= 0.01, so the product of up to ~100 bins' f stays far from underflow; one log
  // per 64 bins instead of one per bin (the log was most of the cost).
  double sum_log_f = 0, prod_f = 1, var_state = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double ph = phi[static_cast<std::size_t>(i)];
    const double var_pred = ph * ph * var_state + q * (1.0 - ph * ph);
    const double f = var_pred + (1.0 - q);
    const double gain = var_pred / f;
    for (Eigen::Index c = 0; c < k; ++c) {
      const auto cu = static_cast<std::size_t>(c);
      v[cu] = z(i, c) - ph * state[cu];
      state[cu] = ph * state[cu] + gain * v[cu];
    }
    var_state = var_pred * (1.0 - gain);
    prod_f *= f;
    if ((i & 63) == 63) {
      sum_log_f += std::log(prod_f);
      prod_f = 1;
    }
    for (Eigen::Index a = 0; a < k; ++a) {
      const double va = v[static_cast<std::size_t>(a)] / f;
      for (Eigen::Index b = a; b < k; ++b) m(a, b) += va * v[static_cast<std::size_t>(b)];
    }
  }
  sum_log_f += std::log(prod_f);
  const SmallMatrix mxx = m.bottomRightCorner(p, p).selfadjointView<Eigen::Upper>();
  const SmallVector mxy = m.row(0).tail(p).transpose();
  const Eigen::LDLT<SmallMatrix> ldlt(mxx);
  const double rss = m(0, 0) - mxy.dot(ldlt.solve(mxy));
  Profile out;
  const auto dof = static_cast<double>(n - p);
  if (!(rss > 0) || ldlt.info() != Eigen::Success) return out;
  out.sigma2 = rss / dof;
  out.minus2_loglik = sum_log_f + ldlt.vectorD().array().log().sum() + dof * std::log(out.sigma2);
  return out;
}

/// Median spacing of neighbouring bins of one run, s (1 when times are not given).
double bin_spacing_s(std::span<const double> t_s, std::span<const int> segment) {
  std::vector<double> gaps;
  for (std::size_t i = 1; i < t_s.size(); ++i) {
    if (segment.empty() || segment[i] == segment[i - 1]) gaps.push_back(t_s[i] - t_s[i - 1]);
  }
  if (gaps.empty()) return 1.0;
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<long>(gaps.size() / 2), gaps.end());
  return std::max(gaps[gaps.size() / 2], 1e-9);
}

struct Best {
  double log_tau = 0, q = 0;
  Profile profile;
};

/// What the search needs: the rows [y X], the bin times and runs.
struct Problem {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> z;
  std::span<const double> t_s;
  std::span<const int> segment;
  std::vector<double> phi;  // scratch
};

/// Grid search over log tau in [lo, hi] and q in [q_lo, q_hi], `steps` points each way.
void search(Best& best, Problem& pb, double lo, double hi, double q_lo, double q_hi, int steps) {
  for (int a = 0; a < steps; ++a) {
    const double log_tau = lo + (hi - lo) * a / (steps - 1);
    step_corrs(pb.phi, pb.t_s, pb.segment, pb.z.rows(), std::exp(log_tau));
    for (int b = 0; b < steps; ++b) {
      const double q = std::clamp(q_lo + (q_hi - q_lo) * b / (steps - 1), 0.0, kMaxShare);
      const Profile pr = reml_profile(pb.z, pb.phi, q);
      if (pr.minus2_loglik < best.profile.minus2_loglik) best = {log_tau, q, pr};
    }
  }
}

}  // namespace

ErrorModel estimate_error_model(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                std::span<const double> t_s, std::span<const int> segment) {
  const Eigen::Index n = x.rows(), p = x.cols();
  ErrorModel model;
  if (n < p + 4 || p + 1 > kMaxColumns) {  // too few bins to estimate two more parameters
    const Eigen::VectorXd b = x.colPivHouseholderQr().solve(y);
    model.sigma_dph = std::sqrt((y - x * b).squaredNorm() / static_cast<double>(n - p));
    return model;
  }
  const double spacing_s = bin_spacing_s(t_s, segment);
  const double span_s = std::max(time_of(t_s, n - 1) - time_of(t_s, 0), spacing_s);
  // tau from a third of a bin (the Gauss-Markov part is then white) to ten record lengths
  // (then it is a drift the constant and the regressors mostly absorb).
  const double lo = std::log(spacing_s / 3.0), hi = std::log(10.0 * span_s);
  Problem pb{{}, t_s, segment, {}};
  pb.z.resize(n, p + 1);
  pb.z.col(0) = y;
  pb.z.rightCols(p) = x;
  Best best;
  best.log_tau = lo;
  step_corrs(pb.phi, t_s, segment, n, std::exp(lo));
  best.profile = reml_profile(pb.z, pb.phi, 0.0);  // iid: q = 0
  search(best, pb, lo, hi, 0.0, kMaxShare, kCoarseSteps);
  // Finer searches around the best point so far, each on a grid a third as wide.
  double half_tau = (hi - lo) / (kCoarseSteps - 1), half_q = kMaxShare / (kCoarseSteps - 1);
  for (int round = 0; round < kRefinements; ++round) {
    const Best centre = best;
    search(best, pb, std::max(centre.log_tau - half_tau, lo),
           std::min(centre.log_tau + half_tau, hi), std::max(centre.q - half_q, 0.0),
           std::min(centre.q + half_q, kMaxShare), 5);
    half_tau /= 2;
    half_q /= 2;
  }
  if (best.q <= 0) {  // no correlated part found: independent bins
    model.sigma_dph = std::sqrt(best.profile.sigma2);
    return model;
  }
  model.method = "ar1+white (REML)";
  model.on_search_boundary = best.q >= kMaxShare || best.log_tau >= hi - 1e-9;
  model.corr_time_s = std::exp(best.log_tau);
  model.correlated_share = best.q;
  model.sigma_dph = std::sqrt(best.profile.sigma2);
  model.rho_per_bin = std::exp(-spacing_s / model.corr_time_s);
  return model;
}

Eigen::VectorXd ols_variances_under(const ErrorModel& model, const Eigen::MatrixXd& q_basis,
                                    const Eigen::MatrixXd& r_inv, std::span<const double> t_s,
                                    std::span<const int> segment) {
  const Eigen::Index n = q_basis.rows();
  const double q = model.correlated_share, tau_s = model.corr_time_s;
  // C Q with C = (1 - q) I + q P, P_ij = exp(-|t_i - t_j| / tau) (0 across runs), in O(n p):
  // P v = f + b - v with f_i = v_i + phi_i f_(i-1) and b_i = v_i + phi_(i+1) b_(i+1), as
  // exp(-|t_i - t_j| / tau) is the product of the step correlations between them. No n x n
  // matrix is formed: a fit over thousands of bins needs no more memory than its data.
  Eigen::MatrixXd cq = q_basis;
  if (q > 0 && tau_s > 0) {
    std::vector<double> phi;
    step_corrs(phi, t_s, segment, n, tau_s);
    Eigen::MatrixXd fwd = q_basis, bwd = q_basis;
    for (Eigen::Index i = 1; i < n; ++i)
      fwd.row(i) += phi[static_cast<std::size_t>(i)] * fwd.row(i - 1);
    for (Eigen::Index i = n - 2; i >= 0; --i)
      bwd.row(i) += phi[static_cast<std::size_t>(i + 1)] * bwd.row(i + 1);
    cq = (1.0 - q) * q_basis + q * (fwd + bwd - q_basis);
  }
  // Var(b) = s^2 (X'X)^-1 X' C X (X'X)^-1 = s^2 R^-1 (Q' C Q) R^-T with X = Q R: formed from the
  // orthonormal Q, it does not cancel as the product with (X'X)^-1 does when X is ill conditioned.
  const Eigen::MatrixXd meat = q_basis.transpose() * cq;
  return (r_inv * meat * r_inv.transpose()).diagonal() * (model.sigma_dph * model.sigma_dph);
}

}  // namespace station::compensation
