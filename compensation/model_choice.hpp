// Which regression terms the bins hold, each candidate model compared with its own error model.
//
// The restricted likelihood that estimate_error_model maximizes (correlated_errors.hpp) depends on
// the regressors through log |X' V^-1 X|: REML likelihoods of models with different terms are not
// comparable (Verbeke & Molenberghs, Linear Mixed Models for Longitudinal Data, 2000, sec. 6.2.1;
// Welham & Thompson, JRSS B 59:701, 1997). Models are compared by the maximum likelihood instead,
// each maximized over the joint choice of its coefficients and its error model (white +
// Gauss-Markov + rate random walk: the same search space as the error model's, searched again for
// each model). A term the error model could otherwise absorb as a "drift" then has to beat the
// drift on likelihood: the base model's best error model competes with the extended model's best.
//
// For nested models the difference of the two deviances, LR = D(base) - D(base + term), is the
// likelihood-ratio statistic, chi^2 with 1 degree of freedom under the base model (Wilks, Ann.
// Math. Stat. 9:60, 1938); the nuisance parameters of the error model are maximized in both, so
// their boundaries do not enter the degrees of freedom of the term tested.
// Pure maths: no I/O.
#pragma once

#include <Eigen/Dense>
#include <span>
#include <vector>

#include "compensation/fit.hpp"

namespace station::compensation {

/// -2 x the maximum log-likelihood (constants dropped) of y = X_s b + e for each column subset s
/// of `x` (0-based column indices), each maximized over its own error model. `x` should be well
/// conditioned (an orthonormal basis of the base model with each extra column orthogonalized
/// against it); at most reml::kMaxColumns - 1 columns. With fewer than the largest subset's
/// columns + kMinBinsForErrorModelExtra bins only independent bins are considered (then the
/// differences are the classical least-squares likelihood ratios n log(RSS_0 / RSS_1)).
/// Subset 0 is the base; each is searched on the coarse grid, the base refined around its best,
/// another subset only when its ratio to the base comes within reach of `refine_from_lr` (the
/// bound a test will hold it to): elsewhere its deviance is the coarse grid's, a little high.
std::vector<double> max_ml_deviances(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                     std::span<const std::vector<int>> subsets,
                                     std::span<const double> t_s, std::span<const int> segment,
                                     double refine_from_lr = 0);

/// An orthonormal basis of the first `p` columns of `x` followed by each later column
/// orthogonalized against that basis and scaled to unit norm: the base model and each candidate
/// column well conditioned for max_ml_deviances. A candidate that the base columns already span
/// is left as zeros (its subset's fit then fails and reads as no improvement).
Eigen::MatrixXd base_and_candidates(const Eigen::MatrixXd& x, Eigen::Index p);

/// The likelihood ratio of spec + t against spec for each t of `tried`, every model with its own
/// error model; 0 where one cannot be fitted. `bound_lr`: the bound a test will hold them to
/// (max_ml_deviances refines the ones within reach of it).
std::vector<double> extension_likelihood_ratios(const ModelInput& in, const ModelSpec& spec,
                                                const std::vector<Term>& tried, double bound_lr);

}  // namespace station::compensation
