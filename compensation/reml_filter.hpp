// The restricted likelihood of the white + Gauss-Markov + random-walk error model of
// correlated_errors.hpp, by a two-state Kalman filter over the bins, several error models per
// pass. Internal to compensation/: correlated_errors.cpp searches over it.
#pragma once

#include <Eigen/Dense>
#include <limits>
#include <span>
#include <vector>

namespace station::compensation::reml {

/// Error models evaluated in one pass over the bins: their filters run side by side, so the
/// per-bin work vectorizes and one model's division waits on no other's.
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

/// Columns of z (1..p; y is column 0) a regression uses.
using Columns = std::vector<int>;

/// -2 x the maximum log-likelihood (not the restricted one), the regression coefficients and s^2
/// concentrated out at their maximum-likelihood values (s^2 = RSS_GLS / n), constants dropped:
///   -2 l = sum log f + n log(RSS_GLS / n)        (Harvey 1989, sec. 3.4, eq. 3.4.10),
/// of y on each column subset under each model, out[model * subsets.size() + subset]. Unlike
/// the restricted likelihood, whose term log |X' F^-1 X| changes with the columns, these compare
/// across subsets: the same y, the same n, nested column sets give likelihood ratios.
void ml_deviances(const RowMajor& z, const std::vector<double>& dt_h, std::span<const Model> models,
                  std::span<const Columns> subsets, std::span<double> out);

}  // namespace station::compensation::reml
