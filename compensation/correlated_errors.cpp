// REML estimate of an AR(1)-plus-white error model by a Kalman filter, and the OLS covariance
// under it (see the header for the method and its sources).
#include "compensation/correlated_errors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "compensation/error_model_search.hpp"

namespace station::compensation {
namespace {

using namespace model_search;

// The error models averaged: the most likely grid points, at most this many, each at least
// kMinWeight of the best's likelihood.
constexpr std::size_t kMaxComponents = 32;
constexpr double kMinWeight = 1e-3;
/// The coarse grid's most likely points as the model's mixture: weights relative to the best
/// point found, finite ones only, ties kept in grid order. The q = 0 points of every tau are all
/// kept although tau does not matter there: each stands for the slab of small q at its tau, the
/// quadrature weight a uniform prior on q gives it (counted once, white noise came out at 0.83
/// at 1 SE on the paper cycle, above the 0.78 band).
void add_mixture(ErrorModel& model, std::vector<Point>& grid, const Point& best,
                 const Problem& pb) {
  std::vector<Point> kept;
  for (const Point& e : grid) {
    if (!std::isfinite(objective(e, pb)) || !(e.profile.sigma2 > 0)) continue;
    kept.push_back(e);
  }
  std::stable_sort(kept.begin(), kept.end(), [&pb](const Point& a, const Point& b) {
    return objective(a, pb) < objective(b, pb);
  });
  for (const Point& e : kept) {
    const double w = std::exp(-0.5 * (objective(e, pb) - objective(best, pb)));
    if (w < kMinWeight || model.mixture.size() == kMaxComponents) break;
    model.mixture.push_back({e.q > 0 ? std::exp(e.log_tau) : 0, e.q, std::sqrt(e.profile.sigma2),
                             std::sqrt(e.profile.sigma2) * std::sqrt(walk_per_h(pb, e.u)), w});
  }
}

// chi^2(1) at 95 %: a walk whose profile restricted likelihood is within this of the best is not
// excluded by the bins (the profile-likelihood interval; Pawitan, In All Likelihood, 2001, 2.6).
constexpr double kChi2One95 = 3.8415;

/// The largest walk the bins do not exclude at 95 %: the profile of -2 l_R over the walk's size
/// (the coarse grid's best over tau and q at each size), where it crosses best + kChi2One95,
/// linear in the size between grid values; the Gauss-Markov part and s of the point below it.
std::optional<ErrorModel::Component> largest_walk_not_excluded(const std::vector<Point>& grid,
                                                               const Problem& pb, bool& at_edge) {
  at_edge = false;
  std::map<double, const Point*> profile;  // by walk size u, increasing
  double best = std::numeric_limits<double>::infinity();
  for (const Point& e : grid) {
    if (!std::isfinite(e.profile.minus2_loglik) || !(e.profile.sigma2 > 0)) continue;
    auto [it, added] = profile.try_emplace(e.u, &e);
    if (!added && e.profile.minus2_loglik < it->second->profile.minus2_loglik) it->second = &e;
    best = std::min(best, e.profile.minus2_loglik);
  }
  const double bound = best + kChi2One95;
  auto last = profile.end();  // the largest size inside the bound
  for (auto it = profile.begin(); it != profile.end(); ++it)
    if (it->second->profile.minus2_loglik <= bound) last = it;
  if (last == profile.end()) return std::nullopt;
  const Point* inside = last->second;
  double u = last->first;
  if (const auto next = std::next(last); next != profile.end()) {  // crosses between the two
    const double d0 = inside->profile.minus2_loglik, d1 = next->second->profile.minus2_loglik;
    u += (next->first - u) * std::clamp((bound - d0) / (d1 - d0), 0.0, 1.0);
  } else {
    at_edge = u >= kWalkHi;  // even the search's largest walk is inside
  }
  if (u <= kWalkLo) return std::nullopt;
  const double s2 = inside->profile.sigma2;
  return ErrorModel::Component{inside->q > 0 ? std::exp(inside->log_tau) : 0, inside->q,
                               std::sqrt(s2), std::sqrt(s2 * walk_per_h(pb, u)), 1.0};
}

/// Independent bins: sigma from the OLS residuals (RSS / (n - p)); the prior kept as given
/// (walk_assessed false: it weighed nothing).
ErrorModel ols_only(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const NoisePrior* prior) {
  ErrorModel model;
  if (prior != nullptr && !prior->empty()) model.prior = *prior;
  const Eigen::VectorXd b = x.colPivHouseholderQr().solve(y);
  model.sigma_dph = std::sqrt((y - x * b).squaredNorm() / static_cast<double>(x.rows() - x.cols()));
  return model;
}

/// What the search says of a walk: without a prior the largest it does not exclude; with one,
/// whether the prior's walk lies beyond the largest it spans.
void assess_walk(ErrorModel& model, const std::vector<Point>& grid, const Point& best,
                 const Problem& pb) {
  model.walk_assessed = true;
  model.walk_search_max_dph_rt_h = std::sqrt(best.profile.sigma2 * walk_per_h(pb, kWalkHi));
  if (pb.prior == nullptr)
    model.walk_not_excluded = largest_walk_not_excluded(grid, pb, model.walk_bound_at_search_edge);
  else if (const auto k = prior_walk_dph_rt_h(*pb.prior, pb.span_h))
    model.prior_walk_beyond_search = *k > pb.prior->trust_factor * model.walk_search_max_dph_rt_h;
}

/// The model's point estimate from the search's best point (none: independent bins).
ErrorModel with_best_point(ErrorModel model, const Point& best, const Problem& pb, double tau_hi,
                           double spacing_s) {
  if (best.q <= 0 && best.u <= kWalkLo && model.mixture.empty())
    return model;  // no correlated part: independent bins
  model.method = "white+gm+rrw (REML)";
  model.on_search_boundary =
      best.q >= kMaxShare || best.u >= kWalkHi || (best.q > 0 && best.log_tau >= tau_hi - 1e-9);
  if (best.q > 0) {
    model.corr_time_s = std::exp(best.log_tau);
    model.correlated_share = best.q;
    model.rho_per_bin = std::exp(-spacing_s / model.corr_time_s);
  }
  model.rrw_dph_per_sqrt_h = model.sigma_dph * std::sqrt(walk_per_h(pb, best.u));
  return model;
}

}  // namespace

ErrorModel estimate_error_model(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                std::span<const double> t_s, std::span<const int> segment,
                                const NoisePrior* prior) {
  Problem pb = make_problem(x, y, t_s, segment);
  return estimate_error_model(pb, x, y, prior);
}

ErrorModel estimate_error_model(Problem& pb, const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                const NoisePrior* prior) {
  const Eigen::Index n = x.rows(), p = x.cols();
  if (n < p + kMinBinsForErrorModelExtra || p < 1 || p + 1 > reml::kMaxColumns)
    return ols_only(x, y, prior);  // too few bins to estimate three more parameters
  ErrorModel model;
  pb.prior = prior != nullptr && !prior->empty() ? prior : nullptr;
  if (pb.prior != nullptr) model.prior = *pb.prior;
  const double hi = pb.tau_hi, spacing_s = pb.spacing_s;
  Point best = iid_point(pb);
  std::vector<Point> grid;
  pb.record = &grid;
  // The coarse grid on every column of pb: the lack-of-fit search (model_choice.hpp) starts
  // from the same points. The refinement is this search's own, on the base columns alone.
  search(best, pb, whole_box(pb), kCoarseSteps, pb.candidates() > 0);
  pb.record = nullptr;
  refine(best, pb);
  if (!std::isfinite(best.profile.minus2_loglik) || !(best.profile.sigma2 > 0)) {
    // No error model fits (a noise-free or constant bias): the OLS errors, as with too few bins.
    return ols_only(x, y, pb.prior);
  }
  model.sigma_dph = std::sqrt(best.profile.sigma2);
  add_mixture(model, grid, best, pb);
  assess_walk(model, grid, best, pb);
  pb.prior = nullptr;  // the prior weighs this search only
  return with_best_point(model, best, pb, hi, spacing_s);
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
