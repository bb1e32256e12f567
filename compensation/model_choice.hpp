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

#include "compensation/error_model_search.hpp"
#include "compensation/fit.hpp"

namespace station::compensation {

/// The lack-of-fit search's problem (error_model_search.hpp) for the fit of `in` on `spec`:
/// y, the fit's orthonormal basis `q_basis` (X = Q R of the column-scaled design) and each
/// candidate of `tried` orthogonalized against it and scaled to unit norm (a candidate the base
/// already spans is left as zeros: its fit reads as no improvement). estimate_error_model on it
/// evaluates its coarse grid on every column, which the candidates' search then reuses.
model_search::Problem lack_of_fit_problem(const ModelInput& in, const ModelSpec& spec,
                                          const Eigen::MatrixXd& q_basis,
                                          const std::vector<Term>& tried);

/// -2 x the maximum log-likelihood (constants dropped) of y on the base ([0]) and on the base
/// with each candidate ([1 + k]), each maximized over its own error model. With fewer than the
/// base's columns + 1 + kMinBinsForErrorModelExtra bins only independent bins are considered
/// (then the differences are the classical least-squares likelihood ratios n log(RSS_0 / RSS_1)).
/// Each is searched on the coarse grid (the points pb already holds are not evaluated again),
/// the base refined around its best, a candidate only when its ratio to the base comes within
/// reach of `refine_from_lr` (the bound a test will hold it to): elsewhere its deviance is the
/// coarse grid's, a little high.
std::vector<double> max_ml_deviances(model_search::Problem& pb, double refine_from_lr = 0);

/// The likelihood ratio of the base + each candidate of pb against the base, every model with its
/// own error model; 0 where one cannot be fitted. `bound_lr`: the bound a test will hold them to
/// (max_ml_deviances refines the ones within reach of it).
std::vector<double> extension_likelihood_ratios(model_search::Problem& pb, double bound_lr);

/// The same for spec + t against spec for each t of `tried`, on a problem made here.
std::vector<double> extension_likelihood_ratios(const ModelInput& in, const ModelSpec& spec,
                                                const std::vector<Term>& tried, double bound_lr);

}  // namespace station::compensation
