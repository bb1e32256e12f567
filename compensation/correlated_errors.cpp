// REML estimate of an AR(1)-plus-white error model by a Kalman filter, and the OLS covariance
// under it (see the header for the method and its sources).
#include "compensation/correlated_errors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "compensation/reml_filter.hpp"

namespace station::compensation {
namespace {

constexpr double kMaxShare = 0.99;  // q = 1 with tau -> infinity makes the filter degenerate
constexpr int kCoarseSteps = 6;     // 6 x 6 x 6 grid over log tau, q and the walk's size, then
constexpr int kRefinements = 3;     // 3 rounds of 3 x 3 x 3 around the best point
// The error models averaged: the most likely grid points, at most this many, each at least
// kMinWeight of the best's likelihood.
constexpr std::size_t kMaxComponents = 32;
constexpr double kMinWeight = 1e-3;
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

using reml::Profile;

struct Point {
  double log_tau = 0, q = 0, u = 0;  // u: log10 of the walk's variance over a run, in s^2
  Profile profile;
  /// Two grid points are one error model when q, the walk and (where q > 0) tau agree.
  bool same_model(const Point& o) const {
    return q == o.q && u == o.u && (q == 0 || log_tau == o.log_tau);
  }
};

/// What the search needs: the rows [y X], the bin times and runs.
struct Problem {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> z;
  std::span<const double> t_s;
  std::span<const int> segment;
  double span_h = 1;
  std::vector<double> dt_h;
  std::map<double, std::vector<double>> phi;  // step correlations by log tau, made once each
  std::vector<Point>* record = nullptr;

  const std::vector<double>& phi_at(double log_tau) {
    auto [it, added] = phi.try_emplace(log_tau);
    if (added) step_corrs(it->second, t_s, segment, z.rows(), std::exp(log_tau));
    return it->second;
  }
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

/// Grid search over the box, `steps` points each way, in grid order (the first of equally likely
/// points wins). A model the grid repeats (q = 0 at every tau, a clamped edge, the best point so
/// far) is evaluated once; the others go reml::kLanes to a pass.
void search(Point& best, Problem& pb, const Box& b, int steps) {
  std::vector<Point> pts;
  for (int a = 0; a < steps; ++a)
    for (int c = 0; c < steps; ++c)
      for (int d = 0; d < steps; ++d)
        pts.push_back({at(b.tau_lo, b.tau_hi, a, steps),
                       std::clamp(at(b.q_lo, b.q_hi, c, steps), 0.0, kMaxShare),
                       std::clamp(at(b.u_lo, b.u_hi, d, steps), kWalkLo, kWalkHi),
                       {}});
  std::vector<Point> unique{best};
  std::vector<std::size_t> which(pts.size());
  std::vector<reml::Model> models;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto it = std::find_if(unique.begin(), unique.end(),
                                 [&](const Point& e) { return e.same_model(pts[i]); });
    which[i] = static_cast<std::size_t>(it - unique.begin());
    if (it != unique.end()) continue;
    unique.push_back(pts[i]);
    models.push_back({&pb.phi_at(pts[i].log_tau), pts[i].q, walk_per_h(pb, pts[i].u)});
  }
  std::vector<Profile> found(models.size());
  reml::profiles(pb.z, pb.dt_h, models, found);
  for (std::size_t j = 0; j < found.size(); ++j) unique[j + 1].profile = found[j];
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i].profile = unique[which[i]].profile;
    if (pb.record) pb.record->push_back(pts[i]);
    if (pts[i].profile.minus2_loglik < best.profile.minus2_loglik) best = pts[i];
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

namespace {

/// Independent bins: sigma from the OLS residuals (RSS / (n - p)).
ErrorModel ols_only(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  ErrorModel model;
  const Eigen::VectorXd b = x.colPivHouseholderQr().solve(y);
  model.sigma_dph = std::sqrt((y - x * b).squaredNorm() / static_cast<double>(x.rows() - x.cols()));
  return model;
}

/// Finer searches around the best point so far, each on a grid half as wide.
void refine(Point& best, Problem& pb, double lo, double hi) {
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
}

}  // namespace

ErrorModel estimate_error_model(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                std::span<const double> t_s, std::span<const int> segment) {
  const Eigen::Index n = x.rows(), p = x.cols();
  ErrorModel model;
  if (n < p + kMinBinsForErrorModelExtra || p < 1 ||
      p + 1 > reml::kMaxColumns) {  // too few bins to estimate three more parameters
    return ols_only(x, y);
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
  const reml::Model iid{&pb.phi_at(lo), 0, 0};
  reml::profiles(pb.z, pb.dt_h, {&iid, 1}, {&best.profile, 1});
  std::vector<Point> grid;
  pb.record = &grid;
  search(best, pb, {lo, hi, 0.0, kMaxShare, kWalkLo, kWalkHi}, kCoarseSteps);
  pb.record = nullptr;
  refine(best, pb, lo, hi);
  if (!std::isfinite(best.profile.minus2_loglik) || !(best.profile.sigma2 > 0)) {
    // No error model fits (a noise-free or constant bias): the OLS errors, as with too few bins.
    return ols_only(x, y);
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

/// A row of the design basis, on the stack (at most reml::kMaxColumns terms).
using RowVec = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, reml::kMaxColumns>;

/// The pieces of Q' C Q for one design basis, each in units of s^2: Q'Q (white), Q' W Q / w (the
/// walk, per unit w) and Q' P Q per correlation time (Gauss-Markov). A mixture's models share
/// them: the walk's piece is one matrix, and its models take at most kCoarseSteps values of tau.
class Meats {
 public:
  Meats(const Eigen::MatrixXd& q_basis, std::span<const double> t_s, std::span<const int> segment)
      : q_(q_basis), t_s_(t_s), segment_(segment), white_(q_basis.transpose() * q_basis) {
    step_hours(dt_h_, t_s, segment, q_basis.rows());
  }
  const Eigen::MatrixXd& white() const { return white_; }

  /// Q' W Q / w with W_ij = min(h_i, h_j), h the hours since the run's first bin: as
  /// min(h_i, h_j) = sum of dh_k over k <= min(i, j) in the run, v' W v = sum_k dh_k (suffix sum
  /// of v from k)^2, one backward pass with no n x n matrix.
  const Eigen::MatrixXd& walk() {
    if (walk_.size() > 0) return walk_;
    const Eigen::Index n = q_.rows();
    walk_ = Eigen::MatrixXd::Zero(q_.cols(), q_.cols());
    RowVec suffix = RowVec::Zero(q_.cols());  // within a run: the sum of rows i..(run's end)
    for (Eigen::Index i = n - 1; i >= 0; --i) {
      suffix += q_.row(i);
      const double dt = dt_h_[static_cast<std::size_t>(i)];
      if (dt < 0) {  // bin i starts its run
        suffix.setZero();
        continue;
      }
      walk_.selfadjointView<Eigen::Upper>().rankUpdate(suffix.transpose(), dt);
    }
    walk_ = walk_.selfadjointView<Eigen::Upper>();
    return walk_;
  }

  /// Q' P Q with P_ij = exp(-|t_i - t_j| / tau) within a run: P = L + L' - I with L the lower
  /// triangle, L v the forward recursion f_i = v_i + phi_i f_(i-1), so Q' P Q = S + S' - Q'Q with
  /// S = Q' L Q = sum_i Q_i' f_i, one pass over the rows.
  const Eigen::MatrixXd& gauss_markov(double tau_s) {
    for (const auto& [tau, m] : gm_)
      if (tau == tau_s) return m;
    const Eigen::Index n = q_.rows();
    step_corrs(phi_, t_s_, segment_, n, tau_s);
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(q_.cols(), q_.cols());
    RowVec f = RowVec::Zero(q_.cols());
    for (Eigen::Index i = 0; i < n; ++i) {
      f = q_.row(i) + phi_[static_cast<std::size_t>(i)] * f;
      s.noalias() += q_.row(i).transpose() * f;
    }
    gm_.emplace_back(tau_s, s + s.transpose() - white_);
    return gm_.back().second;
  }

 private:
  const Eigen::MatrixXd& q_;
  std::span<const double> t_s_;
  std::span<const int> segment_;
  Eigen::MatrixXd white_, walk_;
  std::vector<double> dt_h_, phi_;
  std::vector<std::pair<double, Eigen::MatrixXd>> gm_;
};

/// Var(b) = s^2 (X'X)^-1 X' C X (X'X)^-1 = s^2 R^-1 (Q' C Q) R^-T with X = Q R, for one model:
/// formed from the orthonormal Q, it does not cancel as the product with (X'X)^-1 does when X is
/// ill conditioned.
Eigen::VectorXd variances_one(const ErrorModel::Component& c, Meats& meats,
                              const Eigen::MatrixXd& r_inv) {
  if (!(c.sigma_dph > 0)) return Eigen::VectorXd::Zero(r_inv.rows());
  const double q = c.corr_time_s > 0 ? c.correlated_share : 0.0;
  Eigen::MatrixXd meat = (1 - q) * meats.white();
  if (q > 0) meat += q * meats.gauss_markov(c.corr_time_s);
  if (c.rrw_dph_per_sqrt_h > 0)
    meat += std::pow(c.rrw_dph_per_sqrt_h / c.sigma_dph, 2) * meats.walk();
  return (r_inv * meat * r_inv.transpose()).diagonal() * (c.sigma_dph * c.sigma_dph);
}

}  // namespace

Eigen::VectorXd ols_variances_under(const ErrorModel& model, const Eigen::MatrixXd& q_basis,
                                    const Eigen::MatrixXd& r_inv, std::span<const double> t_s,
                                    std::span<const int> segment) {
  Meats meats(q_basis, t_s, segment);
  if (model.mixture.empty()) {
    return variances_one(
        {model.corr_time_s, model.correlated_share, model.sigma_dph, model.rrw_dph_per_sqrt_h, 1.0},
        meats, r_inv);
  }
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(q_basis.cols());
  double weights = 0;
  for (const auto& c : model.mixture) {
    sum += c.weight * variances_one(c, meats, r_inv).array().log().matrix();
    weights += c.weight;
  }
  return (sum / weights).array().exp().matrix();
}

}  // namespace station::compensation
