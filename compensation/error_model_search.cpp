// The search over the error models (see the header).
#include "compensation/error_model_search.hpp"

#include <algorithm>
#include <cmath>

namespace station::compensation::model_search {
namespace {

bool same_run(std::span<const int> segment, Eigen::Index i, Eigen::Index j) {
  return segment.empty() ||
         segment[static_cast<std::size_t>(i)] == segment[static_cast<std::size_t>(j)];
}

double time_of(std::span<const double> t_s, Eigen::Index i) {
  return t_s.empty() ? static_cast<double>(i) : t_s[static_cast<std::size_t>(i)];
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

double at(double lo, double hi, int i, int steps) {
  return lo + (hi - lo) * i / (steps - 1);
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

}  // namespace

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

double walk_per_h(const Problem& pb, double u) {
  return u <= kWalkLo ? 0.0 : std::pow(10.0, u) / pb.span_h;
}

/// The box's grid, `steps` points each way, clamped to the search's range, in grid order.
std::vector<Point> grid_points(const Box& b, int steps) {
  std::vector<Point> pts;
  for (int a = 0; a < steps; ++a)
    for (int c = 0; c < steps; ++c)
      for (int d = 0; d < steps; ++d)
        pts.push_back({at(b.tau_lo, b.tau_hi, a, steps),
                       std::clamp(at(b.q_lo, b.q_hi, c, steps), 0.0, kMaxShare),
                       std::clamp(at(b.u_lo, b.u_hi, d, steps), kWalkLo, kWalkHi),
                       {},
                       kNoDeviances});
  return pts;
}

/// Evaluates each point: its restricted likelihood, and with `all_columns` its maximum
/// likelihoods. A model the points repeat (q = 0 at every tau, a clamped edge), `known` or one
/// pb.evaluated holds is evaluated once: every pass gives a model the same bits. The new ones go
/// reml::kLanes to a pass; with `all_columns` they are kept in pb.evaluated.
void evaluate(std::vector<Point>& pts, Problem& pb, const Point& known, bool all_columns) {
  std::vector<const Point*> from(pts.size(), nullptr);
  std::vector<Point> fresh;
  std::map<std::array<double, 3>, std::size_t> fresh_at;
  std::vector<std::size_t> fresh_of(pts.size());
  std::vector<reml::Model> models;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto key = pts[i].model_key();
    if (known.same_model(pts[i])) {
      from[i] = &known;
    } else if (const auto it = pb.evaluated.find(key); it != pb.evaluated.end()) {
      from[i] = &it->second;
    } else {
      const auto [at, added] = fresh_at.try_emplace(key, fresh.size());
      fresh_of[i] = at->second;
      if (!added) continue;
      fresh.push_back(pts[i]);
      models.push_back({&pb.phi_at(pts[i].log_tau), pts[i].q, walk_per_h(pb, pts[i].u)});
    }
  }
  std::vector<Profile> found(models.size());
  std::vector<reml::Deviances> ml(all_columns ? models.size() : 0);
  reml::evaluate(pb.z, pb.base, pb.dt_h, models, found, ml);
  for (std::size_t j = 0; j < fresh.size(); ++j) {
    fresh[j].profile = found[j];
    if (all_columns) fresh[j].ml = ml[j];
  }
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Point& e = from[i] != nullptr ? *from[i] : fresh[fresh_of[i]];
    pts[i].profile = e.profile;
    pts[i].ml = e.ml;
  }
  if (all_columns)
    for (const Point& e : fresh) pb.evaluated.try_emplace(e.model_key(), e);
}

/// Grid search over the box for the most likely point (the first of equally likely points wins).
void search(Point& best, Problem& pb, const Box& b, int steps, bool all_columns) {
  std::vector<Point> pts = grid_points(b, steps);
  evaluate(pts, pb, best, all_columns);
  for (const Point& e : pts) {
    if (pb.record) pb.record->push_back(e);
    if (objective(e, pb) < objective(best, pb)) best = e;
  }
}

/// The box of refinement round `round` around c: the coarse grid's spacing halved each round.
Box refined_box(const Point& c, int round, const Problem& pb) {
  const double shrink = std::ldexp(1.0, -round) / (kCoarseSteps - 1);
  const double half_tau = (pb.tau_hi - pb.tau_lo) * shrink, half_q = kMaxShare * shrink,
               half_u = (kWalkHi - kWalkLo) * shrink;
  return {std::max(c.log_tau - half_tau, pb.tau_lo),
          std::min(c.log_tau + half_tau, pb.tau_hi),
          std::max(c.q - half_q, 0.0),
          std::min(c.q + half_q, kMaxShare),
          std::max(c.u - half_u, kWalkLo),
          std::min(c.u + half_u, kWalkHi)};
}

/// Finer searches around the best point so far, each on a grid half as wide.
void refine(Point& best, Problem& pb) {
  for (int round = 0; round < kRefinements; ++round)
    search(best, pb, refined_box(best, round, pb), 3, false);
}

/// The search's problem: rows [y X], run starts, tau's range from a third of a bin (the
/// Gauss-Markov part is then white) to ten record lengths (then it is a drift the constant and
/// the regressors mostly absorb).
Problem make_problem(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                     std::span<const double> t_s, std::span<const int> segment,
                     const Eigen::MatrixXd& candidates) {
  const Eigen::Index n = x.rows(), p = x.cols(), c = candidates.cols();
  Problem pb;
  pb.t_s = t_s;
  pb.segment = segment;
  pb.spacing_s = bin_spacing_s(t_s, segment);
  const double span_s = std::max(longest_run_s(t_s, segment, n), pb.spacing_s);
  pb.span_h = span_s / 3600.0;
  pb.tau_lo = std::log(pb.spacing_s / 3.0);
  pb.tau_hi = std::log(10.0 * span_s);
  pb.base = p;
  pb.z.resize(n, p + 1 + c);
  pb.z.col(0) = y;
  pb.z.middleCols(1, p) = x;
  if (c > 0) pb.z.rightCols(c) = candidates;
  step_hours(pb.dt_h, t_s, segment, n);
  return pb;
}

/// Independent bins: the search's starting point, evaluated.
Point iid_point(Problem& pb) {
  Point iid;
  iid.log_tau = pb.tau_lo;
  iid.u = kWalkLo;  // q = 0 and no walk
  std::vector<Point> one{iid};
  evaluate(one, pb, Point{0, -1, 0, {}, kNoDeviances}, true);  // q = -1: no model repeats it
  return one[0];
}

double walk_dph_rt_h(const Point& e, const Problem& pb) {
  return std::sqrt(e.profile.sigma2 * walk_per_h(pb, e.u));
}

double objective(const Point& e, const Problem& pb) {
  if (pb.prior == nullptr) return e.profile.minus2_loglik;
  const double white_sd = std::sqrt((1 - e.q) * e.profile.sigma2);
  return e.profile.minus2_loglik +
         noise_prior_penalty(*pb.prior, white_sd, walk_dph_rt_h(e, pb), pb.spacing_s, pb.span_h);
}

Box whole_box(const Problem& pb) {
  return {pb.tau_lo, pb.tau_hi, 0.0, kMaxShare, kWalkLo, kWalkHi};
}

}  // namespace station::compensation::model_search
