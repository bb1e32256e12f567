// What the acceptance analyses (scale_factor, turn_on, positions) share: a result that is either
// a value or why it could not be computed, and weighted least squares with its covariance.
//
// Failure shape: fit.hpp refuses bad data with a DataError whose message names the point and
// the field ("bin 3: temperature nan is not a finite number"). The acceptance analyses run
// inside a protocol step where one bad ladder must not stop the run, so they return the same
// one-line message as a value (NotComputed) instead of throwing.
//
// Covariance rule (all three analyses): C = (X' W X)^-1 with W = diag(1/se_i^2) from the
// caller's standard errors; when dof = n - p > 0 and chi2/dof > 1 (chi2 = sum w_i r_i^2), C is
// multiplied by chi2/dof. This is the Particle Data Group's scale factor S = sqrt(chi2/dof),
// applied only when S > 1 (Review of Particle Physics, "Introduction", section on averaging and
// fitting; the "Birge ratio"): errors the data show to be larger than stated inflate the
// standard errors; data that scatter less than stated never shrink them.
// Except a rate ladder's line and its asymmetry fit (scale_factor.hpp): ordinary_least_squares
// below. Their scale factors are *defined* as the least-squares straight line over the ladder
// (equal weights: every dwell is as long), its residuals are the gyro's nonlinearity, a figure
// of its own and not a sign of understated errors, and the fit's errors are those of that
// estimator under the points' stated errors. The station-level Monte Carlo (tests/station/
// test_acceptance_coverage.cpp) found both alternatives wrong: the chi2/dof rule let the
// nonlinearity pass for K's error (K within 1 SE in 100 %), and weights 1/se^2 from the points'
// own noise estimates (9 dof each, a factor 6 apart by chance) moved the line wherever the
// luckiest points pulled it (an asymmetry of -104 ppm for a gyro's +26 over the same points).
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace station::compensation {

/// Why a figure could not be computed: one line naming the input and what is wrong with it.
struct NotComputed {
  std::string message;
};

/// Either a T or why it could not be computed (NotComputed). Never throws on construction.
template <class T>
class [[nodiscard]] Computed {
 public:
  Computed(T value) : v_(std::move(value)) {}        // NOLINT: implicit by design
  Computed(NotComputed why) : v_(std::move(why)) {}  // NOLINT: implicit by design
  /// True when the value is there.
  bool ok() const { return std::holds_alternative<T>(v_); }
  explicit operator bool() const { return ok(); }
  /// The value; throws std::logic_error carrying the message when there is none.
  const T& value() const {
    if (!ok()) throw std::logic_error("not computed: " + error());
    return std::get<T>(v_);
  }
  const T& operator*() const { return value(); }
  const T* operator->() const { return &value(); }
  /// Why not; empty when ok().
  const std::string& error() const {
    static const std::string kNone;
    return ok() ? kNone : std::get<NotComputed>(v_).message;
  }

 private:
  std::variant<T, NotComputed> v_;
};

/// A weighted least-squares fit y = X b (see the covariance rule above).
struct WeightedFit {
  Eigen::VectorXd coefficients;  ///< b
  Eigen::MatrixXd covariance;    ///< of b, after the chi2/dof rule
  Eigen::VectorXd residuals;     ///< y - X b, in y's unit (unweighted)
  double chi2 = 0;               ///< sum of (residual / se)^2
  std::size_t dof = 0;           ///< rows - columns
  double se_scale = 1;           ///< sqrt of the factor applied to the covariance (>= 1)
};

/// Weighted least squares by Householder QR of the weighted, column-scaled design (no normal
/// equations). `se` holds each row's standard error (> 0, finite; checked by the caller).
/// NotComputed when rows < columns or the columns are linearly dependent (|R_jj| below 1e-12
/// of the largest after scaling each column to unit norm).
Computed<WeightedFit> weighted_least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                             const Eigen::VectorXd& se);

/// Ordinary (equal-weight) least squares with the estimator's exact covariance under the rows'
/// stated errors: b = L y with L = (X'X)^-1 X', so Cov(b) = L diag(se^2) L' (the covariance of
/// a linear function of independent y: Seber & Lee, Linear Regression Analysis, 2nd ed.,
/// theorem 1.3). No chi2/dof rule; chi2 = sum (r_i / se_i)^2 and se_scale = 1 for the record.
/// NotComputed as weighted_least_squares.
Computed<WeightedFit> ordinary_least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                                             const Eigen::VectorXd& se);

/// Variance of g(b) by the delta method: grad' C grad (Casella & Berger, Statistical
/// Inference, 2nd ed., Theorem 5.5.24 and its multivariate form).
double delta_method_variance(const Eigen::VectorXd& grad, const Eigen::MatrixXd& covariance);

/// `angle_deg` wrapped to (-180, 180].
double wrap_deg(double angle_deg);

}  // namespace station::compensation
