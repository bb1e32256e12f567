// The search over the error models of correlated_errors.hpp (white + Gauss-Markov + rate random
// walk): a coarse grid over log tau, the correlated share q and the walk's size, refined around
// the best point, each point's likelihood from the Kalman filter of reml_filter.hpp. Internal to
// compensation/: estimate_error_model (restricted likelihood) and the model comparison of
// model_choice.hpp (maximum likelihood per column subset) both search this one space.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <limits>
#include <map>
#include <span>
#include <vector>

#include "compensation/noise_prior.hpp"
#include "compensation/reml_filter.hpp"

namespace station::compensation::model_search {

using reml::Profile;

inline constexpr double kMaxShare = 0.99;  // q = 1 with tau -> infinity: a degenerate filter
inline constexpr int kCoarseSteps = 6;     // 6 x 6 x 6 grid over log tau, q and the walk's size,
inline constexpr int kRefinements = 3;     // then 3 rounds of 3 x 3 x 3 around the best point

/// Correlation of the Gauss-Markov part from bin i-1 to bin i, for each bin (0 across runs).
void step_corrs(std::vector<double>& phi, std::span<const double> t_s, std::span<const int> segment,
                Eigen::Index n, double tau_s);
/// Hours from bin i-1 to bin i within a run; -1 where bin i starts a run.
void step_hours(std::vector<double>& dt_h, std::span<const double> t_s,
                std::span<const int> segment, Eigen::Index n);

/// Deviances not (yet) found: each infinite.
inline constexpr reml::Deviances kNoDeviances = [] {
  reml::Deviances d{};
  d.fill(std::numeric_limits<double>::infinity());
  return d;
}();

struct Point {
  double log_tau = 0, q = 0, u = 0;  // u: log10 of the walk's variance over a run, in s^2
  Profile profile;
  /// The maximum likelihood search (model_choice.hpp): -2 l of the base, then of the base with
  /// each candidate; infinite where the point was evaluated on the base columns alone.
  reml::Deviances ml = kNoDeviances;
  /// Two grid points are one error model when q, the walk and (where q > 0) tau agree.
  bool same_model(const Point& o) const {
    return q == o.q && u == o.u && (q == 0 || log_tau == o.log_tau);
  }
  /// What same_model compares, as a key.
  std::array<double, 3> model_key() const { return {q, u, q == 0 ? 0.0 : log_tau}; }
};

/// What the search needs: the rows [y X C] (the base columns X, then the lack-of-fit candidates
/// C of model_choice.hpp, if any), the bin times and runs, and every point evaluated on all of
/// them (the error model's coarse grid serves the candidates' search too).
struct Problem {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> z;
  Eigen::Index base = 0;  ///< X's columns: z's columns 1..base
  std::span<const double> t_s;
  std::span<const int> segment;
  double span_h = 1, spacing_s = 1, tau_lo = 0, tau_hi = 0;  // tau's range: log s
  std::vector<double> dt_h;
  std::map<double, std::vector<double>> phi;  // step correlations by log tau, made once each
  std::vector<Point>* record = nullptr;
  const NoisePrior* prior = nullptr;                 // the part's noise (noise_prior.hpp), if given
  std::map<std::array<double, 3>, Point> evaluated;  // on every column, by Point::model_key

  Eigen::Index candidates() const { return z.cols() - 1 - base; }

  const std::vector<double>& phi_at(double log_tau) {
    auto [it, added] = phi.try_emplace(log_tau);
    if (added) step_corrs(it->second, t_s, segment, z.rows(), std::exp(log_tau));
    return it->second;
  }
};

struct Box {
  double tau_lo, tau_hi, q_lo, q_hi, u_lo, u_hi;
};

// The walk's size: log10 of its variance over the longest run in units of s^2, from 1e-3 (read
// as no walk at all) to 100.
inline constexpr double kWalkLo = -3, kWalkHi = 2;

/// The walk's variance per hour (units of s^2) at size u.
double walk_per_h(const Problem& pb, double u);
/// A point's walk, deg/h/sqrt(h), at its restricted-likelihood s^2.
double walk_dph_rt_h(const Point& e, const Problem& pb);
/// What the restricted-likelihood search minimizes: -2 l_R, plus -2 log prior with pb.prior.
double objective(const Point& e, const Problem& pb);
/// The search's problem for y on the columns of x, bins at t_s in runs `segment`; with
/// `candidates`, their columns follow x's (at most reml::kMaxColumns columns in all, y's too).
Problem make_problem(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                     std::span<const double> t_s, std::span<const int> segment,
                     const Eigen::MatrixXd& candidates = {});
/// The whole search box of a problem.
Box whole_box(const Problem& pb);
/// The box of refinement round `round` around c: the coarse grid's spacing halved each round.
Box refined_box(const Point& c, int round, const Problem& pb);
/// The box's grid, `steps` points each way, clamped to the search's range, in grid order.
std::vector<Point> grid_points(const Box& b, int steps);
/// Evaluates each point: its restricted likelihood on the base columns, and with `all_columns`
/// its maximum likelihoods too (kept in pb.evaluated). A model pb.evaluated or `known` holds is
/// taken from there.
void evaluate(std::vector<Point>& pts, Problem& pb, const Point& known, bool all_columns);
/// Grid search over the box for the point of least objective(), evaluated as `evaluate` does.
void search(Point& best, Problem& pb, const Box& b, int steps, bool all_columns);
/// Finer searches around the best point so far, each on a grid half as wide.
void refine(Point& best, Problem& pb);
/// Independent bins (q = 0, no walk): the search's starting point, evaluated on every column.
Point iid_point(Problem& pb);

}  // namespace station::compensation::model_search
