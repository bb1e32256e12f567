// Models compared by their maximum likelihoods, each with its own error model (see the header).
#include "compensation/model_choice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "compensation/correlated_errors.hpp"
#include "compensation/error_model_search.hpp"

namespace station::compensation {
namespace {

using namespace model_search;

// The most the refinement rounds lowered a deviance below the coarse grid's best, over the 700
// fits of the LackOfFit Monte-Carlo (every subset refined): 2.07, mean 0.2. A subset whose
// coarse ratio falls short of the bound by more than this could not reach it; 3 leaves margin.
// Test LackOfFit.RefiningOnlyNearTheBoundChangesNoDecision holds it: refining every candidate
// changes no decision (its ratios move by at most 0.04 there).
constexpr double kRefinementGain = 3.0;

/// Each subset's best point among `pts` (its lowest deviance), kept in `best`.
void keep_best(std::vector<Point>& best, const std::vector<Point>& pts) {
  for (const Point& e : pts)
    for (std::size_t s = 0; s < best.size(); ++s)
      if (e.ml[s] < best[s].ml[s]) best[s] = e;
}

/// The refinement rounds around subset s's best point (every subset keeps what they find).
void refine_subset(std::vector<Point>& best, std::size_t s, Problem& pb) {
  for (int round = 0; round < kRefinements; ++round) {
    const Point centre = best[s];
    std::vector<Point> pts = grid_points(refined_box(centre, round, pb), 3);
    evaluate(pts, pb, centre);
    keep_best(best, pts);
  }
}

}  // namespace

std::vector<double> max_ml_deviances(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                     std::span<const std::vector<int>> subsets,
                                     std::span<const double> t_s, std::span<const int> segment,
                                     double refine_from_lr) {
  std::vector<reml::Columns> cols;
  std::size_t widest = 0;
  for (const auto& s : subsets) {
    cols.emplace_back();
    for (const int c : s) cols.back().push_back(c + 1);  // z's column 0 is y
    widest = std::max(widest, s.size());
  }
  Problem pb = make_problem(x, y, t_s, segment);
  pb.subsets = cols;
  std::vector<Point> best(subsets.size(), iid_point(pb));
  const bool enough = x.rows() >= static_cast<Eigen::Index>(widest) + kMinBinsForErrorModelExtra;
  if (enough) {
    std::vector<Point> pts = grid_points(whole_box(pb), kCoarseSteps);
    evaluate(pts, pb, best[0]);
    keep_best(best, pts);
    refine_subset(best, 0, pb);
    for (std::size_t s = 1; s < best.size(); ++s)
      if (best[0].ml[0] - best[s].ml[s] >= refine_from_lr - kRefinementGain)
        refine_subset(best, s, pb);
  }
  std::vector<double> out(subsets.size());
  for (std::size_t s = 0; s < best.size(); ++s) out[s] = best[s].ml[s];
  return out;
}

Eigen::MatrixXd base_and_candidates(const Eigen::MatrixXd& x, Eigen::Index p) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(x.leftCols(p));
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(x.rows(), p);
  Eigen::MatrixXd out(x.rows(), x.cols());
  out.leftCols(p) = q;
  for (Eigen::Index j = p; j < x.cols(); ++j) {
    Eigen::VectorXd c = x.col(j) - q * (q.transpose() * x.col(j));
    c -= q * (q.transpose() * c);  // twice is enough (Giraud et al., Numer. Math. 101:87, 2005)
    const double norm = c.norm();
    const double scale = x.col(j).norm();
    out.col(j) = norm > 1e-10 * scale ? Eigen::VectorXd(c / norm) : Eigen::VectorXd::Zero(x.rows());
  }
  return out;
}

std::vector<double> extension_likelihood_ratios(const ModelInput& in, const ModelSpec& spec,
                                                const std::vector<Term>& tried, double bound_lr) {
  ModelSpec all = spec;
  all.terms.insert(all.terms.end(), tried.begin(), tried.end());
  const auto p = static_cast<Eigen::Index>(spec.terms.size() + 1);
  const Eigen::MatrixXd x = base_and_candidates(design_matrix(in, all), p);
  const Eigen::Map<const Eigen::VectorXd> y(in.bias_dph.data(),
                                            static_cast<Eigen::Index>(in.bias_dph.size()));
  std::vector<std::vector<int>> subsets(tried.size() + 1);
  for (int j = 0; j < p; ++j) subsets[0].push_back(j);
  for (std::size_t k = 0; k < tried.size(); ++k) {
    subsets[k + 1] = subsets[0];
    subsets[k + 1].push_back(static_cast<int>(p + static_cast<Eigen::Index>(k)));
  }
  const std::vector<double> dev = max_ml_deviances(x, y, subsets, in.t_s, in.segment, bound_lr);
  std::vector<double> lr(tried.size());
  for (std::size_t k = 0; k < tried.size(); ++k)
    lr[k] = std::isfinite(dev[k + 1]) && std::isfinite(dev[0]) ? dev[0] - dev[k + 1] : 0.0;
  return lr;
}

}  // namespace station::compensation
