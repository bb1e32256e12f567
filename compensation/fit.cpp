// Least-squares fit of the thermal bias model with Eigen's Householder QR.
#include "compensation/fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "compensation/earth_rate.hpp"
#include "compensation/fit_diagnostics.hpp"
#include "compensation/limits.hpp"
#include "compensation/model_choice.hpp"

namespace station::compensation {
namespace {

// Belsley, Kuh & Welsch, Regression Diagnostics (1980), ch. 3: a condition index of the
// column-scaled design matrix above 30 signals a moderate-to-strong near dependency.
constexpr double kCollinearCondition = 30.0;
// Past this the standard errors are meaningless: the terms are linearly dependent.
constexpr double kSingularCondition = 1e10;

// A result that is not finite is refused rather than stored or printed.
void check_result(const FitResult& r) {
  for (std::size_t j = 0; j < r.coefficients.size(); ++j) {
    if (!std::isfinite(r.coefficients[j]) || !std::isfinite(r.std_errors[j]) ||
        !std::isfinite(r.std_errors_ols[j]) || !std::isfinite(r.std_errors_hac[j])) {
      throw DataError("fit: coefficient " + r.names[j] + " or its standard error is not finite");
    }
  }
  if (!std::isfinite(r.r2) || !std::isfinite(r.residual_rms_dph))
    throw DataError("fit: R^2 or the residual RMS is not finite");
}

}  // namespace

namespace {

/// Newey & West (1987) heteroskedasticity- and autocorrelation-consistent covariance of the
/// scaled coefficients: n/(n-p) A S A, A = (X'X)^-1 = R^-1 R^-T, S = sum_l w_l (G_l + G_l'),
/// G_l = sum_t e_t e_(t-l) x_t x_(t-l)', w_l = 1 - l/(L+1) (Bartlett). Rows in time order.
Eigen::VectorXd hac_variances(const Eigen::MatrixXd& x, const Eigen::VectorXd& resid,
                              const Eigen::MatrixXd& r_inv, std::size_t lag) {
  const Eigen::MatrixXd u = x.array().colwise() * resid.array();
  Eigen::MatrixXd s = u.transpose() * u;
  const auto n = u.rows();
  for (std::size_t l = 1; l <= lag && static_cast<Eigen::Index>(l) < n; ++l) {
    const auto li = static_cast<Eigen::Index>(l);
    const double w = 1.0 - static_cast<double>(l) / static_cast<double>(lag + 1);
    const Eigen::MatrixXd g = u.bottomRows(n - li).transpose() * u.topRows(n - li);
    s += w * (g + g.transpose());
  }
  const Eigen::MatrixXd a = r_inv * r_inv.transpose();
  const double dof_correction = static_cast<double>(n) / static_cast<double>(n - x.cols());
  return (a * s * a).diagonal() * dof_correction;
}

/// Variance inflation factor of each regressor but the constant: the diagonal of the inverse of
/// the regressors' correlation matrix, VIF_j = 1 / (1 - R_j^2) (Kutner, Nachtsheim, Neter & Li,
/// Applied Linear Statistical Models, 5th ed., 2005, eq. 10.41).
std::vector<double> variance_inflation(const Eigen::MatrixXd& x) {
  const Eigen::Index k = x.cols() - 1;
  if (k <= 1)
    return std::vector<double>(static_cast<std::size_t>(std::max<Eigen::Index>(k, 0)), 1.0);
  Eigen::MatrixXd c = x.rightCols(k).rowwise() - x.rightCols(k).colwise().mean();
  const Eigen::VectorXd norm = c.colwise().norm().transpose();
  c = c * norm.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd corr = c.transpose() * c;
  const Eigen::MatrixXd inv = corr.ldlt().solve(Eigen::MatrixXd::Identity(k, k));
  std::vector<double> vif;
  for (Eigen::Index j = 0; j < k; ++j)
    vif.push_back(std::isfinite(inv(j, j)) && inv(j, j) > 0 ? std::max(inv(j, j), 1.0) : INFINITY);
  return vif;
}

}  // namespace

namespace {

/// Scales each column of `x` to unit norm (better conditioned QR and a meaningful condition
/// number); returns the scales. A column that is zero everywhere is refused naming its term.
Eigen::VectorXd scale_columns(Eigen::MatrixXd& x, const ModelSpec& spec) {
  Eigen::VectorXd scale = x.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < scale.size(); ++j) {
    if (!(scale(j) > 0)) {
      throw DataError("fit: term " + std::string(term_option_name(spec.terms[j - 1])) +
                      " is zero at every point");
    }
  }
  x = x * scale.cwiseInverse().asDiagonal();
  return scale;
}

/// The fit's warnings: collinear terms (Belsley), too few bins for the error model, an error
/// model at the edge of its search.
void add_fit_warnings(FitResult& res, std::size_t n, std::size_t p, bool fixed_error_model) {
  if (res.condition_number > kCollinearCondition) {
    res.warnings.push_back("terms nearly collinear: condition number " +
                           std::to_string(res.condition_number) + " > " +
                           std::to_string(static_cast<int>(kCollinearCondition)) +
                           " (Belsley); coefficients are poorly separated");
  }
  if (!fixed_error_model &&
      static_cast<long>(n) < static_cast<long>(p) + kMinBinsForErrorModelExtra) {
    res.warnings.push_back("only " + std::to_string(n) + " bins: too few to estimate their " +
                           "correlated noise (needs " +
                           std::to_string(static_cast<long>(p) + kMinBinsForErrorModelExtra) +
                           "); the errors assume independent bins and may be too small");
  }
  if (res.error_model.on_search_boundary) {
    res.warnings.push_back(
        "the bins' correlated noise looks like a drift (error model at the edge of its search: " +
        std::to_string(100 * res.error_model.correlated_share) + " % correlated, tau " +
        number_text(res.error_model.corr_time_s) + " s, rate random walk " +
        number_text(res.error_model.rrw_dph_per_sqrt_h) +
        " deg/h/sqrt(h)); the uncertainties are less certain");
  }
  if (res.error_model.prior_walk_beyond_search) {
    res.warnings.push_back(
        "the part's noise implies a rate random walk beyond the largest the error model searches "
        "(" +
        number_text(res.error_model.walk_search_max_dph_rt_h) +
        " deg/h/sqrt(h) for these bins): the errors do not reach it; check the part file's "
        "[noise]");
  }
}

/// The coefficients and their three kinds of standard error, back in the columns' own units.
void set_coefficients(FitResult& res, const ModelSpec& spec, const Eigen::VectorXd& beta_scaled,
                      const Eigen::VectorXd& scale, const Eigen::VectorXd& var_model,
                      const Eigen::VectorXd& var_ols, const Eigen::VectorXd& var_hac) {
  res.names.emplace_back("B0");
  for (Term t : spec.terms) res.names.emplace_back(term_coefficient_name(t));
  for (Eigen::Index j = 0; j < beta_scaled.size(); ++j) {
    res.coefficients.push_back(beta_scaled(j) / scale(j));
    res.std_errors.push_back(std::sqrt(var_model(j)) / scale(j));  // NaN if < 0: refused later
    res.std_errors_ols.push_back(std::sqrt(var_ols(j)) / scale(j));
    res.std_errors_hac.push_back(std::sqrt(std::max(var_hac(j), 0.0)) / scale(j));
  }
}

/// The scaled design's condition number from R's singular values (those of X: X = QR, Q with
/// orthonormal columns); a singular design is refused.
double condition_number(const Eigen::MatrixXd& r) {
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(r).singularValues();
  const double c = sv(sv.size() - 1) > 0 ? sv(0) / sv(sv.size() - 1) : INFINITY;
  if (!(c < kSingularCondition)) {
    throw DataError("fit: the terms are linearly dependent (condition number " + number_text(c) +
                    ")");
  }
  return c;
}

/// R² and the residual RMS from the bias and the residual sum of squares.
void set_goodness(FitResult& res, const Eigen::Ref<const Eigen::VectorXd>& y, double rss) {
  const double mean_y = y.mean();
  const double tss = (y.array() - mean_y).square().sum();
  res.r2 = tss > 0 ? 1.0 - rss / tss : (rss == 0 ? 1.0 : 0.0);
  res.residual_rms_dph = std::sqrt(rss / static_cast<double>(y.size()));
}

/// The coefficients' variances under the error model; with no correlated part the model's
/// covariance is s^2 I and they are the OLS ones exactly.
Eigen::VectorXd model_variances(const ErrorModel& m, const Eigen::MatrixXd& q_basis,
                                const Eigen::MatrixXd& r_inv, const ModelInput& in,
                                const Eigen::VectorXd& var_ols) {
  if (m.correlated_share > 0 || m.rrw_dph_per_sqrt_h > 0 || !m.mixture.empty())
    return ols_variances_under(m, q_basis, r_inv, in.t_s, in.segment);
  return var_ols;
}

/// Without a prior: the standard errors under the largest walk the bins do not exclude.
void set_walk_errors(FitResult& res, const Eigen::MatrixXd& q_basis, const Eigen::MatrixXd& r_inv,
                     const ModelInput& in, const Eigen::VectorXd& scale) {
  if (res.error_model.prior || !res.error_model.walk_not_excluded) return;
  ErrorModel walk;
  const auto& c = *res.error_model.walk_not_excluded;
  walk.corr_time_s = c.corr_time_s, walk.correlated_share = c.correlated_share;
  walk.sigma_dph = c.sigma_dph, walk.rrw_dph_per_sqrt_h = c.rrw_dph_per_sqrt_h;
  const Eigen::VectorXd v = ols_variances_under(walk, q_basis, r_inv, in.t_s, in.segment);
  for (Eigen::Index j = 0; j < v.size(); ++j)
    res.std_errors_walk_not_excluded.push_back(std::sqrt(v(j)) / scale(j));
}

/// The error model: `fixed` if given, else estimated on the basis q_basis; with `lack_of_fit`,
/// on the lack-of-fit problem made there (its candidates' coarse grid evaluated on the way).
ErrorModel error_model_for(const ModelInput& in, const ModelSpec& spec,
                           const Eigen::MatrixXd& q_basis, const Eigen::VectorXd& y,
                           const ErrorModel* fixed, model_search::Problem* lack_of_fit) {
  if (fixed != nullptr) return *fixed;
  const NoisePrior* prior = spec.noise_prior ? &*spec.noise_prior : nullptr;
  if (lack_of_fit == nullptr) return estimate_error_model(q_basis, y, in.t_s, in.segment, prior);
  *lack_of_fit = lack_of_fit_problem(in, spec, q_basis, candidates_for(in, spec));
  return estimate_error_model(*lack_of_fit, q_basis, y, prior);
}

FitResult fit_impl(const ModelInput& in, const ModelSpec& spec, const ErrorModel* fixed,
                   model_search::Problem* lack_of_fit) {
  const std::size_t p = spec.terms.size() + 1;
  const std::size_t n = in.bias_dph.size();
  if (n <= p) {
    throw DataError("too few bins: " + std::to_string(n) + " bins for " + std::to_string(p) +
                    " coefficients (need at least " + std::to_string(p + 1) + ")");
  }
  check_model_input(in, spec);
  Eigen::MatrixXd x = design_matrix(in, spec);
  const Eigen::Map<const Eigen::VectorXd> y(in.bias_dph.data(), static_cast<Eigen::Index>(n));
  std::vector<double> vif = variance_inflation(x);
  const Eigen::VectorXd scale = scale_columns(x, spec);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(x);
  const auto pi = static_cast<Eigen::Index>(p);
  const Eigen::MatrixXd r = qr.matrixQR().topLeftCorner(pi, pi).triangularView<Eigen::Upper>();
  FitResult res;
  res.spec = spec;
  res.vif = std::move(vif);
  res.condition_number = condition_number(r);
  const Eigen::VectorXd beta_scaled = qr.solve(y);
  const Eigen::VectorXd resid = y - x * beta_scaled;
  const double rss = resid.squaredNorm();
  res.n_points = n;
  res.dof = n - p;
  // Var(beta) = s^2 (X'X)^-1 = s^2 R^-1 R^-T, s^2 = RSS / (n - p) (any regression text,
  // e.g. Draper & Smith, Applied Regression Analysis, 3rd ed., eq. 5.2.5).
  const double s2 = rss / static_cast<double>(res.dof);
  const Eigen::MatrixXd r_inv =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(pi, pi));
  const Eigen::VectorXd var_scaled = (r_inv * r_inv.transpose()).diagonal() * s2;
  // The error model sees the orthonormal basis Q of the design (same column space, so the same
  // likelihood) and the sandwich is formed from Q and R^-1: neither squares X's condition.
  const Eigen::MatrixXd q_basis = qr.householderQ() * Eigen::MatrixXd::Identity(x.rows(), pi);
  res.error_model = error_model_for(in, spec, q_basis, y, fixed, lack_of_fit);
  const Eigen::VectorXd var_model =
      model_variances(res.error_model, q_basis, r_inv, in, var_scaled);
  // Lag rule of Newey & West (1994): L = floor(4 (n/100)^(2/9)).
  res.hac_lag = static_cast<std::size_t>(
      std::floor(4.0 * std::pow(static_cast<double>(n) / 100.0, 2.0 / 9.0)));
  // The lack-of-fit extensions (fixed error model) need only the error model's variances: no
  // Newey-West pass over the bins for them.
  const Eigen::VectorXd var_hac =
      fixed != nullptr ? Eigen::VectorXd::Zero(pi) : hac_variances(x, resid, r_inv, res.hac_lag);
  set_coefficients(res, spec, beta_scaled, scale, var_model, var_scaled, var_hac);
  if (fixed == nullptr) set_walk_errors(res, q_basis, r_inv, in, scale);
  set_goodness(res, y, rss);
  add_fit_warnings(res, n, p, fixed != nullptr);
  check_result(res);
  return res;
}

}  // namespace

FitResult fit_model(const ModelInput& in, const ModelSpec& spec) {
  model_search::Problem lack_of_fit;
  FitResult res = fit_impl(in, spec, nullptr, &lack_of_fit);
  diagnose_fit(in, res, lack_of_fit);
  return res;
}

FitResult fit_model_under(const ModelInput& in, const ModelSpec& spec, const ErrorModel& model) {
  return fit_impl(in, spec, &model, nullptr);
}

std::vector<double> predict(const FitResult& fit, const ModelInput& in) {
  const Eigen::MatrixXd x = design_matrix(in, fit.spec);
  const Eigen::Map<const Eigen::VectorXd> beta(fit.coefficients.data(),
                                               static_cast<Eigen::Index>(fit.coefficients.size()));
  const Eigen::VectorXd b = x * beta;
  return {b.data(), b.data() + b.size()};
}

std::vector<double> compensate(const FitResult& fit, const ModelInput& in) {
  std::vector<double> out = predict(fit, in);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = in.bias_dph[i] - out[i];
  return out;
}

}  // namespace station::compensation
