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
constexpr int kCoarseSteps = 6;     // 6 x 6 x 6 grid over log tau, q and the walk's size, then
constexpr int kRefinements = 3;     // 3 rounds of 3 x 3 x 3 around the best point
// The error models averaged: the most likely grid points, at most this many, each at least
// kMinWeight of the best's likelihood.
constexpr std::size_t kMaxComponents = 32;
constexpr double kMinWeight = 1e-3;
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

/// Hours from bin i-1 to bin i within a run; -1 where bin i starts a run.
void step_hours(std::vector<double>& dt_h, std::span<const double> t_s,
                std::span<const int> segment, Eigen::Index n) {
  dt_h.assign(static_cast<std::size_t>(n), -1.0);
  for (Eigen::Index i = 1; i < n; ++i) {
    if (same_run(segment, i, i - 1))
      dt_h[static_cast<std::size_t>(i)] = (time_of(t_s, i) - time_of(t_s, i - 1)) / 3600.0;
  }
}

struct Profile {
  double minus2_loglik = std::numeric_limits<double>::infinity();
  double sigma2 = 0;
};

/// The variance parameters, in units of s^2: white 1 - q, Gauss-Markov q, random walk w per hour.
struct Params {
  double q = 0, w_per_h = 0;
};

/// -2 x restricted log-likelihood (constants dropped) of (tau, q, w) with b and s^2 concentrated
/// out. A two-state Kalman filter (Gauss-Markov g, random walk r; observed g + r + white) runs on
/// y and on every column of X with the same gains (Harvey 1989, 3.4.2): innovations v, their
/// variances f (in units of s^2); GLS normal equations from v/sqrt(f). The walk starts at 0 in
/// each run (its level there is the constant's, and different runs are independent).
/// `z` holds the rows [y_i, x_i] (n x (p+1), row-major); plain loops: it runs ~300 times a fit.
Profile reml_profile(
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& z,
    const std::vector<double>& phi, const std::vector<double>& dt_h, Params pr) {
  const Eigen::Index n = z.rows(), k = z.cols(), p = k - 1;
  // [y X]' F^-1 [y X] of the innovations; sizes bounded by kMaxColumns, so nothing is allocated.
  SmallMatrix m = SmallMatrix::Zero(k, k);
  std::array<double, kMaxColumns> g{}, r{}, v{};
  // f >= 1 - q >= 0.01, so the product of up to ~100 bins' f stays far from underflow; one log
  // per 64 bins instead of one per bin (the log was most of the cost).
  double sum_log_f = 0, prod_f = 1, pgg = 0, pgr = 0, prr = 0;
  const double q = pr.q;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const double ph = phi[iu], dt = dt_h[iu];
    if (dt < 0) {  // a run starts: the walk at 0, the Gauss-Markov part stationary
      std::fill(g.begin(), g.end(), 0.0);
      std::fill(r.begin(), r.end(), 0.0);
      pgg = q;
      pgr = prr = 0;
    } else {
      pgg = ph * ph * pgg + q * (1.0 - ph * ph);
      pgr = ph * pgr;
      prr = prr + pr.w_per_h * dt;
      for (Eigen::Index c = 0; c < k; ++c) g[static_cast<std::size_t>(c)] *= ph;
    }
    const double f = pgg + 2 * pgr + prr + (1.0 - q);
    const double kg = (pgg + pgr) / f, kr = (pgr + prr) / f;
    for (Eigen::Index c = 0; c < k; ++c) {
      const auto cu = static_cast<std::size_t>(c);
      v[cu] = z(i, c) - g[cu] - r[cu];
      g[cu] += kg * v[cu];
      r[cu] += kr * v[cu];
    }
    // P <- P - K f K' (the Joseph form is not needed: f >= 1 - q keeps it well conditioned).
    pgg -= kg * kg * f;
    pgr -= kg * kr * f;
    prr -= kr * kr * f;
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

struct Point {
  double log_tau = 0, q = 0, u = 0;  // u: log10 of the walk's variance over a run, in s^2
  Profile profile;
};

/// What the search needs: the rows [y X], the bin times and runs.
struct Problem {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> z;
  std::span<const double> t_s;
  std::span<const int> segment;
  double span_h = 1;
  std::vector<double> phi, dt_h;  // scratch
  std::vector<Point>* record = nullptr;
};

// The walk's size: log10 of its variance over the longest run in units of s^2, from 1e-3 (read
// as no walk at all) to 100.
constexpr double kWalkLo = -3, kWalkHi = 2;
double walk_per_h(const Problem& pb, double u) {
  return u <= kWalkLo ? 0.0 : std::pow(10.0, u) / pb.span_h;
}

struct Box {
  double tau_lo, tau_hi, q_lo, q_hi, u_lo, u_hi;
};

double at(double lo, double hi, int i, int steps) {
  return lo + (hi - lo) * i / (steps - 1);
}

/// Grid search over the box, `steps` points each way.
void search(Point& best, Problem& pb, const Box& b, int steps) {
  for (int a = 0; a < steps; ++a) {
    const double log_tau = at(b.tau_lo, b.tau_hi, a, steps);
    step_corrs(pb.phi, pb.t_s, pb.segment, pb.z.rows(), std::exp(log_tau));
    for (int c = 0; c < steps; ++c) {
      const double q = std::clamp(at(b.q_lo, b.q_hi, c, steps), 0.0, kMaxShare);
      for (int d = 0; d < steps; ++d) {
        const double u = std::clamp(at(b.u_lo, b.u_hi, d, steps), kWalkLo, kWalkHi);
        const Profile pr = reml_profile(pb.z, pb.phi, pb.dt_h, {q, walk_per_h(pb, u)});
        if (pb.record) pb.record->push_back({log_tau, q, u, pr});
        if (pr.minus2_loglik < best.profile.minus2_loglik) best = {log_tau, q, u, pr};
      }
    }
  }
}

/// The longest time one run spans, s (the whole series when no runs are given).
double longest_run_s(std::span<const double> t_s, std::span<const int> segment, Eigen::Index n) {
  double longest = 0;
  Eigen::Index first = 0;
  for (Eigen::Index i = 1; i <= n; ++i) {
    if (i < n && same_run(segment, i, i - 1)) continue;
    longest = std::max(longest, time_of(t_s, i - 1) - time_of(t_s, first));
    first = i;
  }
  return longest;
}

/// The coarse grid's most likely points as the model's mixture: weights relative to the best
/// point found, finite ones only, ties kept in grid order. The q = 0 points of every tau are all
/// kept although tau does not matter there: each stands for the slab of small q at its tau, the
/// quadrature weight a uniform prior on q gives it (counted once, white noise came out at 0.83
/// at 1 SE on the paper cycle, above the 0.78 band).
void add_mixture(ErrorModel& model, std::vector<Point>& grid, const Point& best,
                 const Problem& pb) {
  std::vector<Point> kept;
  for (const Point& e : grid) {
    if (!std::isfinite(e.profile.minus2_loglik) || !(e.profile.sigma2 > 0)) continue;
    kept.push_back(e);
  }
  std::stable_sort(kept.begin(), kept.end(), [](const Point& a, const Point& b) {
    return a.profile.minus2_loglik < b.profile.minus2_loglik;
  });
  for (const Point& e : kept) {
    const double w = std::exp(-0.5 * (e.profile.minus2_loglik - best.profile.minus2_loglik));
    if (w < kMinWeight || model.mixture.size() == kMaxComponents) break;
    model.mixture.push_back({e.q > 0 ? std::exp(e.log_tau) : 0, e.q, std::sqrt(e.profile.sigma2),
                             std::sqrt(e.profile.sigma2) * std::sqrt(walk_per_h(pb, e.u)), w});
  }
}

}  // namespace

ErrorModel estimate_error_model(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                std::span<const double> t_s, std::span<const int> segment) {
  const Eigen::Index n = x.rows(), p = x.cols();
  ErrorModel model;
  if (n < p + 5 || p + 1 > kMaxColumns) {  // too few bins to estimate three more parameters
    const Eigen::VectorXd b = x.colPivHouseholderQr().solve(y);
    model.sigma_dph = std::sqrt((y - x * b).squaredNorm() / static_cast<double>(n - p));
    return model;
  }
  const double spacing_s = bin_spacing_s(t_s, segment);
  const double span_s = std::max(longest_run_s(t_s, segment, n), spacing_s);
  // tau from a third of a bin (the Gauss-Markov part is then white) to ten record lengths
  // (then it is a drift the constant and the regressors mostly absorb).
  const double lo = std::log(spacing_s / 3.0), hi = std::log(10.0 * span_s);
  Problem pb{{}, t_s, segment, span_s / 3600.0, {}, {}};
  pb.z.resize(n, p + 1);
  pb.z.col(0) = y;
  pb.z.rightCols(p) = x;
  step_hours(pb.dt_h, t_s, segment, n);
  Point best;
  best.log_tau = lo;
  best.u = kWalkLo;  // q = 0 and no walk: independent bins
  step_corrs(pb.phi, t_s, segment, n, std::exp(lo));
  best.profile = reml_profile(pb.z, pb.phi, pb.dt_h, {});  // iid
  std::vector<Point> grid;
  pb.record = &grid;
  search(best, pb, {lo, hi, 0.0, kMaxShare, kWalkLo, kWalkHi}, kCoarseSteps);
  pb.record = nullptr;
  // Finer searches around the best point so far, each on a grid half as wide.
  double half_tau = (hi - lo) / (kCoarseSteps - 1), half_q = kMaxShare / (kCoarseSteps - 1);
  double half_u = (kWalkHi - kWalkLo) / (kCoarseSteps - 1);
  for (int round = 0; round < kRefinements; ++round) {
    const Point c = best;
    search(best, pb,
           {std::max(c.log_tau - half_tau, lo), std::min(c.log_tau + half_tau, hi),
            std::max(c.q - half_q, 0.0), std::min(c.q + half_q, kMaxShare),
            std::max(c.u - half_u, kWalkLo), std::min(c.u + half_u, kWalkHi)},
           3);
    half_tau /= 2;
    half_q /= 2;
    half_u /= 2;
  }
  if (!std::isfinite(best.profile.minus2_loglik) || !(best.profile.sigma2 > 0)) {
    // No error model fits (a noise-free or constant bias): the OLS errors, as with too few bins.
    const Eigen::VectorXd b = x.colPivHouseholderQr().solve(y);
    model.sigma_dph = std::sqrt((y - x * b).squaredNorm() / static_cast<double>(n - p));
    return model;
  }
  model.sigma_dph = std::sqrt(best.profile.sigma2);
  add_mixture(model, grid, best, pb);
  if (best.q <= 0 && best.u <= kWalkLo && model.mixture.empty())
    return model;  // no correlated part: independent bins
  model.method = "white+gm+rrw (REML)";
  model.on_search_boundary =
      best.q >= kMaxShare || best.u >= kWalkHi || (best.q > 0 && best.log_tau >= hi - 1e-9);
  if (best.q > 0) {
    model.corr_time_s = std::exp(best.log_tau);
    model.correlated_share = best.q;
    model.rho_per_bin = std::exp(-spacing_s / model.corr_time_s);
  }
  model.rrw_dph_per_sqrt_h = model.sigma_dph * std::sqrt(walk_per_h(pb, best.u));
  return model;
}

namespace {
Eigen::VectorXd variances_one(const ErrorModel& model, const Eigen::MatrixXd& q_basis,
                              const Eigen::MatrixXd& r_inv, std::span<const double> t_s,
                              std::span<const int> segment);
}

Eigen::VectorXd ols_variances_under(const ErrorModel& model, const Eigen::MatrixXd& q_basis,
                                    const Eigen::MatrixXd& r_inv, std::span<const double> t_s,
                                    std::span<const int> segment) {
  if (model.mixture.empty()) return variances_one(model, q_basis, r_inv, t_s, segment);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(q_basis.cols());
  double weights = 0;
  for (const auto& c : model.mixture) {
    ErrorModel one;
    one.corr_time_s = c.corr_time_s;
    one.correlated_share = c.correlated_share;
    one.sigma_dph = c.sigma_dph;
    one.rrw_dph_per_sqrt_h = c.rrw_dph_per_sqrt_h;
    sum += c.weight * variances_one(one, q_basis, r_inv, t_s, segment).array().log().matrix();
    weights += c.weight;
  }
  return (sum / weights).array().exp().matrix();
}

namespace {
Eigen::VectorXd variances_one(const ErrorModel& model, const Eigen::MatrixXd& q_basis,
                              const Eigen::MatrixXd& r_inv, std::span<const double> t_s,
                              std::span<const int> segment) {
  const Eigen::Index n = q_basis.rows();
  const double q = model.correlated_share, tau_s = model.corr_time_s;
  if (!(model.sigma_dph > 0)) return Eigen::VectorXd::Zero(q_basis.cols());
  // C Q with C = (1 - q) I + q P, P_ij = exp(-|t_i - t_j| / tau) (0 across runs), in O(n p):
  // P v = f + b - v with f_i = v_i + phi_i f_(i-1) and b_i = v_i + phi_(i+1) b_(i+1), as
  // exp(-|t_i - t_j| / tau) is the product of the step correlations between them. No n x n
  // matrix is formed: a fit over thousands of bins needs no more memory than its data.
  Eigen::MatrixXd cq = q_basis;
  if (model.rrw_dph_per_sqrt_h > 0) {
    // Walk part, in units of s^2: W_ij = w min(h_i, h_j), h the hours since the run's first bin,
    // applied in O(n p) as W v = prefix sums of dh_k times suffix sums of v from k on.
    const double w_per_h = std::pow(model.rrw_dph_per_sqrt_h / model.sigma_dph, 2);
    std::vector<double> dt_h;
    step_hours(dt_h, t_s, segment, n);
    Eigen::MatrixXd suffix = q_basis;
    for (Eigen::Index i = n - 2; i >= 0; --i)
      if (dt_h[static_cast<std::size_t>(i + 1)] >= 0) suffix.row(i) += suffix.row(i + 1);
    Eigen::MatrixXd walk = Eigen::MatrixXd::Zero(n, q_basis.cols());
    for (Eigen::Index i = 1; i < n; ++i) {
      const double dt = dt_h[static_cast<std::size_t>(i)];
      if (dt >= 0) walk.row(i) = walk.row(i - 1) + dt * suffix.row(i);
    }
    cq += w_per_h * walk;
  }
  if (q > 0 && tau_s > 0) {
    std::vector<double> phi;
    step_corrs(phi, t_s, segment, n, tau_s);
    Eigen::MatrixXd fwd = q_basis, bwd = q_basis;
    for (Eigen::Index i = 1; i < n; ++i)
      fwd.row(i) += phi[static_cast<std::size_t>(i)] * fwd.row(i - 1);
    for (Eigen::Index i = n - 2; i >= 0; --i)
      bwd.row(i) += phi[static_cast<std::size_t>(i + 1)] * bwd.row(i + 1);
    cq += q * (fwd + bwd - 2 * q_basis);
  }
  // Var(b) = s^2 (X'X)^-1 X' C X (X'X)^-1 = s^2 R^-1 (Q' C Q) R^-T with X = Q R: formed from the
  // orthonormal Q, it does not cancel as the product with (X'X)^-1 does when X is ill conditioned.
  const Eigen::MatrixXd meat = q_basis.transpose() * cq;
  return (r_inv * meat * r_inv.transpose()).diagonal() * (model.sigma_dph * model.sigma_dph);
}

}  // namespace

}  // namespace station::compensation
