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
    evaluate(pts, pb, centre, true);
    keep_best(best, pts);
  }
}

/// Each of `extra`'s columns orthogonalized against the orthonormal columns of q and scaled to
/// unit norm; zeros where q spans it.
Eigen::MatrixXd candidate_columns(const Eigen::MatrixXd& q, const Eigen::MatrixXd& extra) {
  Eigen::MatrixXd out(extra.rows(), extra.cols());
  for (Eigen::Index j = 0; j < extra.cols(); ++j) {
    Eigen::VectorXd c = extra.col(j) - q * (q.transpose() * extra.col(j));
    c -= q * (q.transpose() * c);  // twice is enough (Giraud et al., Numer. Math. 101:87, 2005)
    const double norm = c.norm();
    const double scale = extra.col(j).norm();
    out.col(j) = norm > 1e-10 * scale ? Eigen::VectorXd(c / norm) : Eigen::VectorXd::Zero(q.rows());
  }
  return out;
}

}  // namespace

Problem lack_of_fit_problem(const ModelInput& in, const ModelSpec& spec,
                            const Eigen::MatrixXd& q_basis, const std::vector<Term>& tried) {
  ModelSpec all = spec;
  all.terms.insert(all.terms.end(), tried.begin(), tried.end());
  const auto c = static_cast<Eigen::Index>(tried.size());
  const Eigen::MatrixXd extra = design_matrix(in, all).rightCols(c);
  const Eigen::Map<const Eigen::VectorXd> y(in.bias_dph.data(), q_basis.rows());
  return make_problem(q_basis, y, in.t_s, in.segment, candidate_columns(q_basis, extra));
}

std::vector<double> max_ml_deviances(Problem& pb, double refine_from_lr) {
  std::vector<Point> best(static_cast<std::size_t>(1 + pb.candidates()), iid_point(pb));
  if (pb.z.rows() >= pb.base + 1 + kMinBinsForErrorModelExtra) {
    std::vector<Point> pts = grid_points(whole_box(pb), kCoarseSteps);
    evaluate(pts, pb, best[0], true);
    keep_best(best, pts);
    refine_subset(best, 0, pb);
    for (std::size_t s = 1; s < best.size(); ++s)
      if (best[0].ml[0] - best[s].ml[s] >= refine_from_lr - kRefinementGain)
        refine_subset(best, s, pb);
  }
  std::vector<double> out(best.size());
  for (std::size_t s = 0; s < best.size(); ++s) out[s] = best[s].ml[s];
  return out;
}

std::vector<double> extension_likelihood_ratios(Problem& pb, double bound_lr) {
  const std::vector<double> dev = max_ml_deviances(pb, bound_lr);
  std::vector<double> lr(dev.size() - 1);
  for (std::size_t k = 0; k < lr.size(); ++k)
    lr[k] = std::isfinite(dev[k + 1]) && std::isfinite(dev[0]) ? dev[0] - dev[k + 1] : 0.0;
  return lr;
}

std::vector<double> extension_likelihood_ratios(const ModelInput& in, const ModelSpec& spec,
                                                const std::vector<Term>& tried, double bound_lr) {
  // The basis as fit_model makes it (fit.cpp): the QR of the design with unit-norm columns.
  Eigen::MatrixXd x = design_matrix(in, spec);
  const Eigen::VectorXd scale =
      x.colwise().norm().transpose().unaryExpr([](double v) { return v > 0 ? v : 1.0; });
  x = x * scale.cwiseInverse().asDiagonal();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(x);
  const Eigen::MatrixXd q_basis = qr.householderQ() * Eigen::MatrixXd::Identity(x.rows(), x.cols());
  Problem pb = lack_of_fit_problem(in, spec, q_basis, tried);
  return extension_likelihood_ratios(pb, bound_lr);
}

}  // namespace station::compensation
