// Honest standard errors for least squares over bins whose noise is correlated in time.
//
// A gyro's 600 s bins share bias-instability noise and rate random walk, so the iid OLS formula
// s^2 (X'X)^-1 is optimistic. The bin errors are modelled with the IEEE Std 952-1997 Annex C
// terms that matter over hours: white noise, a first-order Gauss-Markov process ("correlated
// noise"; a flicker floor is well approximated over one record by one such term) and a rate
// random walk, on the bin times:
//   Cov(e_i, e_j) = s^2 [ (1 - q) d_ij + q exp(-|t_i - t_j| / tau) + w min(h_i, h_j) ]
// with h the hours since the run's first bin (the walk's level there is the constant B0's).
// (tau, q, w) are weighed by their restricted likelihood (REML: Patterson & Thompson 1971;
// Harville 1977, JASA 72:320), evaluated in O(n p) by a two-state Kalman filter with the
// regression coefficients and s^2 concentrated out (Harvey, "Forecasting, structural time series
// models and the Kalman filter", 1989, sec. 3.4 and 5.2). The coefficients stay the ordinary
// least-squares ones (the paper's method); their covariance under one error model is the
// sandwich  s^2 (X'X)^-1 X' R X (X'X)^-1  (e.g. Greene, Econometric Analysis, 7th ed., eq. 9-9).
//
// Seventy bins cannot pin (tau, q, w) down: the REML point estimate regresses to the middle of
// its range, and a standard error taken from it alone is often far too small (coverage at 2 SE
// of 0.75-0.90 under Gauss-Markov, flicker and random-walk noise; docs/UNCERTAINTY.md). So the
// variances are averaged over the error models the bins cannot tell apart: the most likely
// points of the search grid (log-uniform prior on tau and w, uniform on q), each weighted by
// its restricted likelihood, averaged on the log scale. This is a likelihood-weighted geometric
// mean, not the Bayesian model average E[Var | theta] (Hoeting, Madigan, Raftery & Volinsky,
// Statistical Science 14:382, 1999), which is always at least as large: the full average over
// the grid covered white noise at 0.94-0.99 (1 SE), far too conservative, while the point
// estimate alone was optimistic. The geometric mean of the 32 most likely points is the
// compromise whose coverage docs/UNCERTAINTY.md measures, noise type by noise type.
// Pure maths: no I/O.
#pragma once

#include <Eigen/Dense>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "compensation/noise_prior.hpp"

namespace station::compensation {

namespace model_search {
struct Problem;
}

/// The fitted error model of a regression's bins.
struct ErrorModel {
  /// "white+gm+rrw (REML)" ("ar1+white (REML)" in fits stored before) or "iid" (too few bins
  /// to estimate, or no correlated part found)
  std::string method = "iid";
  double corr_time_s = 0;       ///< tau of the Gauss-Markov part, s (0: none)
  double correlated_share = 0;  ///< q: share of the stationary variance in the Gauss-Markov part
  double sigma_dph = 0;         ///< s: stationary (white + Gauss-Markov) sd per bin, deg/h
  double rho_per_bin = 0;       ///< exp(-bin spacing / tau): correlation of neighbouring bins
  /// The estimate sits on the edge of what the search allows (q = 0.99 or tau ten record
  /// lengths): the bins look like a drift more than noise, and the errors are less certain.
  bool on_search_boundary = false;
  /// Rate random walk of the bins, deg/h/sqrt(h): Var(e_i - e_j) grows by rrw^2 |t_i - t_j| on
  /// top of the stationary part (0: none).
  double rrw_dph_per_sqrt_h = 0;
  /// The error models the bins cannot rule out, each weighted by its restricted likelihood
  /// (empty: the point estimate above alone). The variances are averaged over them.
  struct Component {
    double corr_time_s = 0, correlated_share = 0, sigma_dph = 0, rrw_dph_per_sqrt_h = 0, weight = 0;
  };
  std::vector<Component> mixture;
  /// The largest rate random walk the bins do not exclude at 95 % (profile restricted
  /// likelihood), with the rest of its error model; empty when the bins exclude every walk.
  /// What a fit without a prior assumed about a walk it cannot see (issue 32).
  std::optional<Component> walk_not_excluded;
  /// The bins do not exclude even the largest walk the search spans: walk_not_excluded is that
  /// edge, a lower bound of what they cannot exclude.
  bool walk_bound_at_search_edge = false;
  /// The search ran (false: too few bins, or no error model fits; nothing was assessed).
  bool walk_assessed = false;
  /// The largest walk the search spans at the fitted s, deg/h/sqrt(h) (0: no search).
  double walk_search_max_dph_rt_h = 0;
  /// The prior's walk lies beyond trust_factor x that largest walk: the prior could not pull the
  /// errors up to it (the fit warns).
  bool prior_walk_beyond_search = false;
  /// The part's noise the model was estimated under (noise_prior.hpp); empty: none given.
  std::optional<NoisePrior> prior;
};

/// Bins beyond the p coefficients the error model needs to estimate anything: with fewer it is
/// "iid" (the OLS errors) and the fit says so.
inline constexpr long kMinBinsForErrorModelExtra = 5;

/// Estimates the error model of y = X b + e by REML: the most likely point, and the mixture of
/// the models the bins cannot rule out. `x` should be well conditioned (pass the
/// orthonormal Q of X = Q R: the likelihood depends only on the column space of X). `t_s` are the
/// bin times (increasing within a segment), `segment` the run each bin came from (bins of different
/// runs are independent; empty: one run). Needs at least p + kMinBinsForErrorModelExtra bins; with
/// fewer the model is "iid" with s^2 = RSS/(n-p).
/// `prior`: the part's noise (noise_prior.hpp), weighing the models with the likelihood.
ErrorModel estimate_error_model(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                std::span<const double> t_s, std::span<const int> segment,
                                const NoisePrior* prior = nullptr);

/// The same on a search problem made for y on the columns of x (error_model_search.hpp), which may
/// carry the lack-of-fit candidates' columns too: its coarse grid is then evaluated on them as well
/// and kept in `pb` for the candidates' own search (model_choice.hpp).
ErrorModel estimate_error_model(model_search::Problem& pb, const Eigen::MatrixXd& x,
                                const Eigen::VectorXd& y, const NoisePrior* prior);

/// Variances of the OLS coefficients of y = X b + e under `model` (its mixture when it has one),
/// with X = Q R (thin QR, Q `q_basis` n x p, `r_inv` = R^-1): the diagonal of s^2 R^-1 Q' C Q R^-T,
/// O(n p).
Eigen::VectorXd ols_variances_under(const ErrorModel& model, const Eigen::MatrixXd& q_basis,
                                    const Eigen::MatrixXd& r_inv, std::span<const double> t_s,
                                    std::span<const int> segment);

}  // namespace station::compensation
