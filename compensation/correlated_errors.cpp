// REML estimate of an AR(1)-plus-white error model by a Kalman filter, and the OLS covariance
// under it (see the header for the method and its sources).
#include "compensation/correlated_errors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace station::compensation {
namespace {

constexpr double kMaxShare = 0.99;  // q = 1 with tau -> infinity makes the filter degenerate

bool same_run(std::span<const int> segment, Eigen::Index i, Eigen::Index j) {
  return segment.empty() ||
         segment[static_cast<std::size_t>(i)] == segment[static_cast<std::size_t>(j)];
}

double time_of(std::span<const double> t_s, Eigen::Index i) {
  return t_s.empty() ? static_cast<double>(i) : t_s[static_cast<std::size_t>(i)];
}

/// Correlation of the Gauss-Markov part from bin i-1 to bin i (0 across runs).
double step_corr(std::span<const double> t_s, std::span<const int> segment, Eigen::Index i,
                 double tau_s) {
  if (i == 0 || !same_run(segment, i, i - 1)) return 0.0;
  return std::exp(-std::abs(time_of(t_s, i) - time_of(t_s, i - 1)) / tau_s);
}

struct Profile {
  double minus2_loglik = std::numeric_limits<double>::infinity();
  double sigma2 = 0;
};

/// -2 x restricted log-likelihood (constants dropped) of (tau, q) with b and s^2 concentrated
/// out. The filter runs on y and on every column of X with the same gains (Harvey 1989, 3.4.2):
/// innovations v, their variances f (in units of s^2); GLS normal equations from v/sqrt(f).
Profile reml_profile(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                     std::span<const double> t_s, std::span<const int> segment, double tau_s,
                     double q) {
  const Eigen::Index n = x.rows(), p = x.cols();
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd c = Eigen::VectorXd::Zero(p), state = Eigen::VectorXd::Zero(p + 1);
  Eigen::VectorXd v(p + 1), z(p + 1);
  double d = 0, sum_log_f = 0, var_state = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double phi = step_corr(t_s, segment, i, tau_s);
    const double var_pred = phi * phi * var_state + q * (1.0 - phi * phi);
    const double f = var_pred + (1.0 - q);
    const double gain = var_pred / f;
    z << y(i), x.row(i).transpose();
    v = z - phi * state;
    state = phi * state + gain * v;
    var_state = var_pred * (1.0 - gain);
    sum_log_f += std::log(f);
    const auto vx = v.tail(p);
    m.noalias() += vx * vx.transpose() / f;
    c += vx * (v(0) / f);
    d += v(0) * v(0) / f;
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
  const double rss = d - c.dot(ldlt.solve(c));
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

/// Grid search over log tau in [lo, hi] and q in [q_lo, q_hi], `steps` points each way.
void search(Best& best, const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
            std::span<const double> t_s, std::span<const int> segment, double lo, double hi,
            double q_lo, double q_hi, int steps) {
  for (int a = 0; a < steps; ++a) {
    const double log_tau = lo + (hi - lo) * a / (steps - 1);
    for (int b = 0; b < steps; ++b) {
      const double q = std::clamp(q_lo + (q_hi - q_lo) * b / (steps - 1), 0.0, kMaxShare);
      const Profile pr = reml_profile(x, y, t_s, segment, std::exp(log_tau), q);
      if (pr.minus2_loglik < best.profile.minus2_loglik) best = {log_tau, q, pr};
    }
  }
}

}  // namespace

ErrorModel estimate_error_model(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                std::span<const double> t_s, std::span<const int> segment) {
  const Eigen::Index n = x.rows(), p = x.cols();
  ErrorModel model;
  if (n < p + 4) {  // too few bins to estimate two more parameters
    const Eigen::VectorXd b = x.colPivHouseholderQr().solve(y);
    model.sigma_dph = std::sqrt((y - x * b).squaredNorm() / static_cast<double>(n - p));
    return model;
  }
  const double spacing_s = bin_spacing_s(t_s, segment);
  const double span_s = std::max(time_of(t_s, n - 1) - time_of(t_s, 0), spacing_s);
  // tau from a third of a bin (the Gauss-Markov part is then white) to ten record lengths
  // (then it is a drift the constant and the regressors mostly absorb).
  const double lo = std::log(spacing_s / 3.0), hi = std::log(10.0 * span_s);
  Best best;
  best.profile = reml_profile(x, y, t_s, segment, std::exp(lo), 0.0);  // iid: q = 0
  search(best, x, y, t_s, segment, lo, hi, 0.0, kMaxShare, 21);
  // Two finer searches around the best point of the grid.
  double step_tau = (hi - lo) / 20, step_q = kMaxShare / 20;
  for (int round = 0; round < 2; ++round) {
    const Best centre = best;
    search(best, x, y, t_s, segment, centre.log_tau - step_tau, centre.log_tau + step_tau,
           std::max(centre.q - step_q, 0.0), std::min(centre.q + step_q, kMaxShare), 9);
    step_tau /= 4;
    step_q /= 4;
  }
  model.method = "ar1+white (REML)";
  model.corr_time_s = std::exp(best.log_tau);
  model.correlated_share = best.q;
  model.sigma_dph = std::sqrt(best.profile.sigma2);
  model.rho_per_bin = std::exp(-spacing_s / model.corr_time_s);
  return model;
}

Eigen::VectorXd ols_variances_under(const ErrorModel& model, const Eigen::MatrixXd& x,
                                    const Eigen::MatrixXd& xtx_inv, std::span<const double> t_s,
                                    std::span<const int> segment) {
  const Eigen::Index n = x.rows();
  const double q = model.correlated_share, tau_s = model.corr_time_s;
  Eigen::MatrixXd r = Eigen::MatrixXd::Identity(n, n);
  if (q > 0 && tau_s > 0) {
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index j = 0; j < i; ++j) {
        if (!same_run(segment, i, j)) continue;
        r(i, j) = r(j, i) = q * std::exp(-std::abs(time_of(t_s, i) - time_of(t_s, j)) / tau_s);
      }
    }
  }
  const Eigen::MatrixXd meat = x.transpose() * r * x;
  return (xtx_inv * meat * xtx_inv).diagonal() * (model.sigma_dph * model.sigma_dph);
}

}  // namespace station::compensation
