// Rate-ladder scale factor, nonlinearity, asymmetry and temperature coefficient
// (definitions and sources in scale_factor.hpp).
#include "compensation/scale_factor.hpp"

#include <algorithm>
#include <cmath>

#include "compensation/limits.hpp"

namespace station::compensation {
namespace {

constexpr double kPpm = 1e6;

// One line naming the point and the field, as fit.hpp's DataError messages do.
std::string point_problem(std::size_t i, const LadderPoint& p) {
  const std::string at = "ladder point " + std::to_string(i) + ": ";
  if (auto e = rate_problem(3600.0 * p.table_rate_dps); !e.empty()) return at + "table " + e;
  if (auto e = rate_problem(p.earth_rate_dph); !e.empty()) return at + "Earth " + e;
  if (auto e = finite_problem(p.output_pps); !e.empty()) return at + "output_pps " + e;
  if (!(std::isfinite(p.output_se_pps) && p.output_se_pps > 0))
    return at + "output_se_pps " + number_text(p.output_se_pps) + " is not a positive number";
  return {};
}

struct UsedPoints {
  Eigen::VectorXd x_arcsec_per_s, y_pps, se_pps, temp_c;  // temp_c: NaN where not given
  std::size_t excluded = 0;
};

Computed<UsedPoints> used_points(std::span<const LadderPoint> points) {
  std::vector<std::size_t> used;
  UsedPoints u;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].rate_in_tolerance) {
      ++u.excluded;
      continue;
    }
    if (auto e = point_problem(i, points[i]); !e.empty()) return NotComputed{e};
    used.push_back(i);
  }
  if (used.size() < kMinLadderPoints)
    return NotComputed{std::to_string(used.size()) + " ladder points in tolerance (" +
                       std::to_string(u.excluded) + " excluded); at least " +
                       std::to_string(kMinLadderPoints) + " needed"};
  const auto n = static_cast<Eigen::Index>(used.size());
  u.x_arcsec_per_s.resize(n), u.y_pps.resize(n), u.se_pps.resize(n), u.temp_c.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const LadderPoint& p = points[used[k]];
    u.x_arcsec_per_s(k) = ladder_input_arcsec_per_s(p);
    u.y_pps(k) = p.output_pps;
    u.se_pps(k) = p.output_se_pps;
    u.temp_c(k) = p.temp_c;
  }
  return u;
}

// y = a + K+ max(x, 0) + K- min(x, 0): one bias, a scale factor per sign (scale_factor.hpp).
void add_asymmetry(const UsedPoints& u, LadderResult& r) {
  const Eigen::VectorXd& x = u.x_arcsec_per_s;
  if (!((x.array() > 0).any() && (x.array() < 0).any())) {
    r.asymmetry_note = "the ladder has no input rate of one sign";
    return;
  }
  Eigen::MatrixXd design(x.size(), 3);
  design.col(0).setOnes();
  design.col(1) = x.cwiseMax(0.0);
  design.col(2) = x.cwiseMin(0.0);
  // K+ and K- of each sign's least-squares line (ordinary least squares: acceptance.hpp).
  const auto fit = ordinary_least_squares(design, u.y_pps, u.se_pps);
  if (!fit) {
    r.asymmetry_note = fit.error();
    return;
  }
  const double kp = fit->coefficients(1), kn = fit->coefficients(2), s = kp + kn;
  ScaleFactorAsymmetry a;
  a.sf_positive_pulse_per_arcsec = kp;
  a.sf_positive_se_pulse_per_arcsec = std::sqrt(fit->covariance(1, 1));
  a.sf_negative_pulse_per_arcsec = kn;
  a.sf_negative_se_pulse_per_arcsec = std::sqrt(fit->covariance(2, 2));
  a.asymmetry_ppm = 2.0 * (kp - kn) / s * kPpm;
  const Eigen::Vector3d grad(0.0, 4.0 * kn / (s * s) * kPpm, -4.0 * kp / (s * s) * kPpm);
  a.asymmetry_se_ppm = std::sqrt(delta_method_variance(grad, fit->covariance));
  a.se_scale = fit->se_scale;
  r.asymmetry = a;
}

// Residuals in ppm of full-scale output: the least-squares linearity (scale_factor.hpp).
void add_nonlinearity(const UsedPoints& u, const WeightedFit& fit, LadderResult& r) {
  const Eigen::VectorXd& x = u.x_arcsec_per_s;
  const double fs_arcsec_per_s = x.cwiseAbs().maxCoeff();
  r.full_scale_dps = fs_arcsec_per_s / 3600.0;
  const double fs_output_pps = std::abs(r.sf_pulse_per_arcsec) * fs_arcsec_per_s;
  const Eigen::VectorXd ppm = fit.residuals / fs_output_pps * kPpm;
  r.nonlinearity_max_ppm_fs = ppm.cwiseAbs().maxCoeff();
  r.nonlinearity_rms_ppm_fs = std::sqrt(ppm.squaredNorm() / static_cast<double>(ppm.size()));
  for (Eigen::Index k = 0; k < x.size(); ++k)
    r.residuals.push_back({x(k) / 3600.0, ppm(k), u.se_pps(k)});
}

}  // namespace

double ladder_input_arcsec_per_s(const LadderPoint& p) {
  // deg/s -> arcsec/s is * 3600; deg/h is arcsec/s already (scale_factor.hpp, "Units").
  return 3600.0 * p.table_rate_dps + p.earth_rate_dph;
}

namespace {

// The line, its nonlinearity and its asymmetry over the used points (scale_factor.hpp).
Computed<LadderResult> fit_ladder(const UsedPoints& u) {
  Eigen::MatrixXd design(u.x_arcsec_per_s.size(), 2);
  design.col(0).setOnes();
  design.col(1) = u.x_arcsec_per_s;
  // K is the least-squares straight line, its residuals the nonlinearity (acceptance.hpp).
  const auto fit = ordinary_least_squares(design, u.y_pps, u.se_pps);
  if (!fit) return NotComputed{"ladder: " + fit.error()};
  const double a = fit->coefficients(0), k = fit->coefficients(1);
  if (!(k != 0.0)) return NotComputed{"ladder: the fitted scale factor is zero"};
  LadderResult r;
  r.sf_pulse_per_arcsec = k;
  r.sf_se_pulse_per_arcsec = std::sqrt(fit->covariance(1, 1));
  r.bias_dph = a / k;  // arcsec/s = deg/h
  r.bias_se_dph =
      std::sqrt(delta_method_variance(Eigen::Vector2d(1.0 / k, -a / (k * k)), fit->covariance));
  add_nonlinearity(u, *fit, r);
  add_asymmetry(u, r);
  r.points_used = static_cast<std::size_t>(u.x_arcsec_per_s.size());
  r.points_excluded = u.excluded;
  r.dof = fit->dof;
  r.chi2 = fit->chi2;
  r.se_scale = fit->se_scale;
  return r;
}

// The points brought to Tc with `tc_ppm_per_c`: y_i - K x_i TC (T_i - Tc) 1e-6.
UsedPoints at_slope_temp(UsedPoints u, double k, double tc_c, double tc_ppm_per_c) {
  for (Eigen::Index i = 0; i < u.y_pps.size(); ++i)
    u.y_pps(i) -= k * u.x_arcsec_per_s(i) * tc_ppm_per_c * 1e-6 * (u.temp_c(i) - tc_c);
  return u;
}

// The drift-corrected figures, TC's error carried by their sensitivity to TC (linear in TC:
// one more fit at TC + 1 ppm/C gives it exactly).
Computed<LadderResult> corrected(const UsedPoints& u, const LadderResult& plain,
                                 const LadderTemperatureModel& tc) {
  const double k = plain.sf_pulse_per_arcsec, t = plain.temp_c;
  auto r = fit_ladder(at_slope_temp(u, k, t, tc.tc_ppm_per_c));
  const auto moved = fit_ladder(at_slope_temp(u, k, t, tc.tc_ppm_per_c + 1.0));
  if (!r || !moved) return r;
  LadderResult out = *r;
  const double dk = (moved->sf_pulse_per_arcsec - out.sf_pulse_per_arcsec) * tc.tc_se_ppm_per_c;
  out.sf_se_pulse_per_arcsec = std::hypot(out.sf_se_pulse_per_arcsec, dk);
  if (out.asymmetry && moved->asymmetry) {
    const double da =
        (moved->asymmetry->asymmetry_ppm - out.asymmetry->asymmetry_ppm) * tc.tc_se_ppm_per_c;
    out.asymmetry->asymmetry_se_ppm = std::hypot(out.asymmetry->asymmetry_se_ppm, da);
  }
  out.temp_c = plain.temp_c;
  out.drift_c = plain.drift_c;
  out.drift_corrected = true;
  return out;
}

}  // namespace

double ladder_slope_temp_c(std::span<const LadderPoint> points) {
  double xm = 0, n = 0;
  for (const auto& p : points) {
    if (!p.rate_in_tolerance) continue;
    if (!std::isfinite(p.temp_c)) return std::nan("");
    xm += ladder_input_arcsec_per_s(p), n += 1;
  }
  if (n < 2) return std::nan("");
  xm /= n;
  double sxx = 0, sxt = 0;
  for (const auto& p : points) {
    if (!p.rate_in_tolerance) continue;
    const double d = ladder_input_arcsec_per_s(p) - xm;
    sxx += d * d, sxt += d * d * p.temp_c;
  }
  return sxx > 0 ? sxt / sxx : std::nan("");
}

Computed<LadderResult> analyze_rate_ladder(std::span<const LadderPoint> points,
                                           std::optional<LadderTemperatureModel> tc) {
  const auto u = used_points(points);
  if (!u) return NotComputed{u.error()};
  auto r = fit_ladder(*u);
  if (!r) return r;
  LadderResult plain = *r;
  plain.temp_c = ladder_slope_temp_c(points);
  if (std::isfinite(plain.temp_c)) plain.drift_c = u->temp_c.maxCoeff() - u->temp_c.minCoeff();
  if (tc && std::isfinite(plain.temp_c) && std::isfinite(tc->tc_ppm_per_c) &&
      std::isfinite(tc->tc_se_ppm_per_c))
    return corrected(*u, plain, *tc);
  if (plain.asymmetry && plain.drift_c > kMaxUncorrectedDriftC) {
    plain.asymmetry->judged = false;
    plain.asymmetry_note = "the plateau drifted " + number_text(plain.drift_c) +
                           " C during the ladder and no temperature coefficient corrects it: "
                           "the asymmetry holds TC x drift, not judged";
  }
  return plain;
}

namespace {

std::string plateau_problem(std::size_t i, const PlateauScaleFactor& p) {
  const std::string at = "plateau " + std::to_string(i) + ": ";
  if (auto e = temp_problem(p.temp_c); !e.empty()) return at + e;
  if (auto e = finite_problem(p.sf_pulse_per_arcsec); !e.empty())
    return at + "sf_pulse_per_arcsec " + e;
  if (!(std::isfinite(p.sf_se_pulse_per_arcsec) && p.sf_se_pulse_per_arcsec > 0))
    return at + "sf_se_pulse_per_arcsec " + number_text(p.sf_se_pulse_per_arcsec) +
           " is not a positive number";
  return {};
}

}  // namespace

Computed<ScaleFactorTemperatureFit> fit_scale_factor_vs_temperature(
    std::span<const PlateauScaleFactor> plateaus, double ref_temp_c) {
  if (auto e = temp_problem(ref_temp_c); !e.empty()) return NotComputed{"T_ref: " + e};
  if (plateaus.size() < 2)
    return NotComputed{std::to_string(plateaus.size()) + " plateaus; at least 2 needed"};
  const auto n = static_cast<Eigen::Index>(plateaus.size());
  Eigen::MatrixXd design(n, 2);
  Eigen::VectorXd sf(n), se(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& p = plateaus[static_cast<std::size_t>(i)];
    if (auto e = plateau_problem(static_cast<std::size_t>(i), p); !e.empty()) return NotComputed{e};
    design(i, 0) = 1.0;
    design(i, 1) = p.temp_c - ref_temp_c;
    sf(i) = p.sf_pulse_per_arcsec;
    se(i) = p.sf_se_pulse_per_arcsec;
  }
  const double span_c = design.col(1).maxCoeff() - design.col(1).minCoeff();
  if (!(span_c >= kMinPlateauSpanC))
    return NotComputed{"the plateaus span " + number_text(span_c) + " C; at least " +
                       number_text(kMinPlateauSpanC) + " C needed for a temperature coefficient"};
  const auto fit = weighted_least_squares(design, sf, se);
  if (!fit) return NotComputed{fit.error()};
  const double k0 = fit->coefficients(0), s = fit->coefficients(1);
  if (!(k0 != 0.0)) return NotComputed{"the scale factor at T_ref is zero"};
  ScaleFactorTemperatureFit t;
  t.ref_temp_c = ref_temp_c;
  t.sf_ref_pulse_per_arcsec = k0;
  t.sf_ref_se_pulse_per_arcsec = std::sqrt(fit->covariance(0, 0));
  t.slope_pulse_per_arcsec_per_c = s;
  t.slope_se_pulse_per_arcsec_per_c = std::sqrt(fit->covariance(1, 1));
  t.tc_ppm_per_c = s / k0 * kPpm;
  const Eigen::Vector2d grad(-s / (k0 * k0) * kPpm, 1.0 / k0 * kPpm);
  t.tc_se_ppm_per_c = std::sqrt(delta_method_variance(grad, fit->covariance));
  t.plateaus = plateaus.size();
  t.dof = fit->dof;
  t.chi2 = fit->chi2;
  t.se_scale = fit->se_scale;
  return t;
}

}  // namespace station::compensation
