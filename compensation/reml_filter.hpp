// The restricted likelihood of the white + Gauss-Markov + random-walk error model of
// correlated_errors.hpp, by a two-state Kalman filter over the bins, several error models per
// pass. Internal to compensation/: correlated_errors.cpp searches over it.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <limits>
#include <span>
#include <vector>

namespace station::compensation::reml {

/// Error models evaluated in one pass over the bins: their filters run side by side, so the
/// per-bin work vectorizes and one model's division waits on no other's. Eight to a pass where
/// the CPU has AVX-512 and more than four are asked; a model's likelihood is the same bits in
/// either.
inline constexpr int kLanes = 4;
/// The filter's columns: y and up to 9 regressors (B0 and the eight terms of fit.hpp).
inline constexpr int kMaxColumns = 10;

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// One error model, in units of s^2: white 1 - q, Gauss-Markov q with the step correlations
/// `phi` (n values: exp(-gap / tau) from bin i-1 to bin i, 0 where a run starts), random walk
/// w per hour.
struct Model {
  const std::vector<double>* phi = nullptr;
  double q = 0, w_per_h = 0;
};

struct Profile {
  double minus2_loglik = std::numeric_limits<double>::infinity();
  double sigma2 = 0;  ///< s^2 at its REML estimate, (deg/h)^2
};

/// -2 x restricted log-likelihood (constants dropped) of each model, with the regression
/// coefficients and s^2 concentrated out. `z` holds the rows [y_i, x_i] (n x (p + 1),
/// p + 1 <= kMaxColumns), `dt_h` the hours from bin i-1 to bin i (-1 where a run starts).
/// Any number of models; they go kLanes at a time.
void profiles(const RowMajor& z, const std::vector<double>& dt_h, std::span<const Model> models,
              std::span<Profile> out);

/// The most candidate columns a pass can carry beside y and one base column.
inline constexpr int kMaxCandidates = kMaxColumns - 2;

/// -2 x the maximum log-likelihood (not the restricted one) of y on the base columns ([0]) and on
/// the base with each candidate column ([1 + k]), infinity where one cannot be fitted.
using Deviances = std::array<double, kMaxCandidates + 1>;

/// Each model's restricted likelihood of y (column 0 of z) on the base columns 1..base, from a
/// pass over those columns alone; or, with `ml` (one per model), from a pass over every column of
/// z, which also gives the maximum likelihood of y on the base and on the base with each later
/// column (a candidate), the regression coefficients and s^2 concentrated out at their
/// maximum-likelihood values (s^2 = RSS_GLS / n), constants dropped:
///   -2 l = sum log f + n log(RSS_GLS / n)        (Harvey 1989, sec. 3.4, eq. 3.4.10).
/// Unlike the restricted likelihood, whose term log |X' F^-1 X| changes with the columns, these
/// compare across column sets: the same y, the same n, nested sets give likelihood ratios.
/// A candidate's RSS is the base's less its Schur complement, e^2 / d (one factorization of the
/// base's X' F^-1 X serves the restricted likelihood and every candidate).
void evaluate(const RowMajor& z, Eigen::Index base, const std::vector<double>& dt_h,
              std::span<const Model> models, std::span<Profile> out, std::span<Deviances> ml = {});

}  // namespace station::compensation::reml
