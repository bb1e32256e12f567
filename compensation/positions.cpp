// Earth-rate projection vs table angle: bias and input-axis misalignment (positions.hpp).
#include "compensation/positions.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "compensation/earth_rate.hpp"
#include "compensation/limits.hpp"

namespace station::compensation {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerDeg = kPi / 180.0;
// cos phi or sin phi below this: the Earth-rate component that carries the figure vanishes.
constexpr double kMinProjection = 1e-9;
// A horizontal axis's projection amplitude over Omega cos phi: cos(elevation)(1 + SF error).
constexpr double kMinHorizontalRatio = 0.5;
constexpr double kMaxHorizontalRatio = 1.5;

std::string point_problem(std::size_t i, const PositionPoint& p) {
  const std::string at = "position " + std::to_string(i) + ": ";
  if (!std::isfinite(p.table_angle_deg) || std::abs(p.table_angle_deg) > kMaxAbsHeadingDeg)
    return at + "table angle " + number_text(p.table_angle_deg) + " deg is not within +-" +
           number_text(kMaxAbsHeadingDeg);
  if (auto e = rate_problem(p.output_dph); !e.empty()) return at + "output " + e;
  if (!(std::isfinite(p.output_se_dph) && p.output_se_dph > 0))
    return at + "output_se_dph " + number_text(p.output_se_dph) + " is not a positive number";
  return {};
}

std::string site_problem(const PositionSite& s) {
  if (!(std::isfinite(s.latitude_deg) && std::abs(s.latitude_deg) <= 90.0))
    return "latitude " + number_text(s.latitude_deg) + " deg is not within +-90";
  if (!std::isfinite(s.table_zero_azimuth_deg) ||
      std::abs(s.table_zero_azimuth_deg) > kMaxAbsHeadingDeg)
    return "table zero azimuth " + number_text(s.table_zero_azimuth_deg) + " deg is not within +-" +
           number_text(kMaxAbsHeadingDeg);
  return {};
}

// A = |(a, b)| and theta0 = atan2(b, a) with their delta-method SEs (positions.hpp).
void set_amplitude_phase(const WeightedFit& w, ProjectionFit& f) {
  const double a = w.coefficients(1), b = w.coefficients(2);
  const double amp = std::hypot(a, b);
  const Eigen::MatrixXd& c = w.covariance;
  f.amplitude_dph = amp;
  f.phase_deg = std::atan2(b, a) / kRadPerDeg;
  if (amp > 0) {
    f.amplitude_se_dph = std::sqrt(delta_method_variance(Eigen::Vector3d(0, a / amp, b / amp), c));
    const Eigen::Vector3d g_phase(0, -b / (amp * amp), a / (amp * amp));
    f.phase_se_deg = std::sqrt(delta_method_variance(g_phase, c)) / kRadPerDeg;
  } else {
    // No direction to differentiate along: the mean of the two variances, phase unknown.
    f.amplitude_se_dph = std::sqrt(0.5 * (c(1, 1) + c(2, 2)));
    f.phase_se_deg = 180.0;
  }
  f.amplitude_resolved = amp > 3.0 * f.amplitude_se_dph;
}

// The gradient of A in (c, a, b), zero when A = 0.
Eigen::Vector3d amplitude_gradient(const WeightedFit& w) {
  const double a = w.coefficients(1), b = w.coefficients(2), amp = std::hypot(a, b);
  return amp > 0 ? Eigen::Vector3d(0, a / amp, b / amp) : Eigen::Vector3d::Zero();
}

// Distinct table angles mod 360 (1e-6 deg apart, across the +-180 seam too): three distinct
// points on a circle are never collinear, so (1, cos, sin) then has full rank. The QR's own
// test cannot see this: after column scaling, sin at 0, 180 and 360 deg (rounding, 1e-16) looks
// like any other column.
std::size_t distinct_angles(std::span<const PositionPoint> points) {
  std::vector<double> a;
  for (const auto& p : points) a.push_back(wrap_deg(p.table_angle_deg));
  std::sort(a.begin(), a.end());
  constexpr double kTolDeg = 1e-6;
  std::size_t n = a.empty() ? 0 : 1;
  for (std::size_t i = 1; i < a.size(); ++i) n += a[i] - a[i - 1] > kTolDeg;
  if (n > 1 && a.front() + 360.0 - a.back() <= kTolDeg) --n;
  return n;
}

Computed<WeightedFit> weighted_projection(std::span<const PositionPoint> points) {
  if (points.size() < kMinPositions)
    return NotComputed{std::to_string(points.size()) + " positions; at least " +
                       std::to_string(kMinPositions) + " needed"};
  for (std::size_t i = 0; i < points.size(); ++i)
    if (auto e = point_problem(i, points[i]); !e.empty()) return NotComputed{e};
  if (const auto d = distinct_angles(points); d < kMinPositions)
    return NotComputed{"positions: " + std::to_string(d) +
                       " distinct table angles (mod 360 deg); at least " +
                       std::to_string(kMinPositions) + " needed to separate bias, cos and sin"};
  const auto n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd x(n, 3);
  Eigen::VectorXd y(n), se(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const PositionPoint& p = points[static_cast<std::size_t>(i)];
    const double th = p.table_angle_deg * kRadPerDeg;
    x.row(i) << 1.0, std::cos(th), std::sin(th);
    y(i) = p.output_dph;
    se(i) = p.output_se_dph;
  }
  auto fit = weighted_least_squares(x, y, se);
  if (!fit) return NotComputed{"positions: " + fit.error()};
  return fit;
}

ProjectionFit projection_from(const WeightedFit& w) {
  ProjectionFit f;
  f.constant_dph = w.coefficients(0);
  f.constant_se_dph = std::sqrt(w.covariance(0, 0));
  set_amplitude_phase(w, f);
  f.residuals_dph.assign(w.residuals.data(), w.residuals.data() + w.residuals.size());
  f.positions = static_cast<std::size_t>(w.residuals.size());
  f.dof = w.dof;
  f.chi2 = w.chi2;
  f.se_scale = w.se_scale;
  return f;
}

bool known_bias_usable(const KnownBias& k) {
  return rate_problem(k.bias_dph).empty() && std::isfinite(k.bias_se_dph) && k.bias_se_dph >= 0;
}

// sin delta_v = (c - B) / (Omega sin phi), its SE from var(c) + var(B) (positions.hpp); left
// empty at the equator or when |c - B| exceeds the vertical Earth rate.
void add_out_of_plane(double vertical_dph, const KnownBias& known, HorizontalAxisResult& r) {
  if (!(std::abs(vertical_dph) > kMinProjection * kEarthRateDph)) return;
  const double u = (r.fit.constant_dph - known.bias_dph) / vertical_dph;
  if (!(std::abs(u) <= 1.0)) return;
  r.out_of_plane_rad = std::asin(u);
  const double se_c = std::hypot(r.fit.constant_se_dph, known.bias_se_dph);
  r.out_of_plane_se_rad = se_c / std::abs(vertical_dph * std::cos(*r.out_of_plane_rad));
}

}  // namespace

Computed<ProjectionFit> fit_earth_rate_projection(std::span<const PositionPoint> points) {
  const auto w = weighted_projection(points);
  if (!w) return NotComputed{w.error()};
  return projection_from(*w);
}

Computed<VerticalAxisResult> analyze_positions_axis_vertical(std::span<const PositionPoint> points,
                                                             const PositionSite& site) {
  if (auto e = site_problem(site); !e.empty()) return NotComputed{e};
  const double phi = site.latitude_deg * kRadPerDeg;
  const double horizontal_dph = kEarthRateDph * std::cos(phi);
  if (!(horizontal_dph > kMinProjection * kEarthRateDph))
    return NotComputed{"at a pole the horizontal Earth rate that reveals a tilt vanishes"};
  const auto w = weighted_projection(points);
  if (!w) return NotComputed{w.error()};
  VerticalAxisResult r;
  r.fit = projection_from(*w);
  const double ratio = r.fit.amplitude_dph / horizontal_dph;  // sin delta
  if (ratio > 1.0)
    return NotComputed{"amplitude " + number_text(r.fit.amplitude_dph) +
                       " deg/h exceeds the horizontal Earth rate " + number_text(horizontal_dph) +
                       " deg/h: wrong latitude, or the axis is not vertical"};
  r.tilt_small_rad = ratio;
  r.tilt_small_se_rad = r.fit.amplitude_se_dph / horizontal_dph;
  r.tilt_rad = std::asin(ratio);
  r.tilt_se_rad = r.tilt_small_se_rad / std::cos(r.tilt_rad);  // d asin(u)/du = 1/cos
  r.tilt_direction_table_deg = wrap_deg(site.table_zero_azimuth_deg - r.fit.phase_deg);
  r.tilt_direction_se_deg = r.fit.phase_se_deg;
  // B = c - Omega sin phi cos delta; dB/dA = tan phi tan delta (positions.hpp).
  r.bias_dph = r.fit.constant_dph - kEarthRateDph * std::sin(phi) * std::cos(r.tilt_rad);
  const Eigen::Vector3d g_bias =
      Eigen::Vector3d(1, 0, 0) + std::tan(phi) * std::tan(r.tilt_rad) * amplitude_gradient(*w);
  r.bias_se_dph = std::sqrt(delta_method_variance(g_bias, w->covariance));
  return r;
}

Computed<HorizontalAxisResult> analyze_positions_axis_horizontal(
    std::span<const PositionPoint> points, const PositionSite& site, double nominal_axis_table_deg,
    std::optional<KnownBias> known_bias) {
  if (auto e = site_problem(site); !e.empty()) return NotComputed{e};
  if (!std::isfinite(nominal_axis_table_deg))
    return NotComputed{"nominal axis angle " + number_text(nominal_axis_table_deg) +
                       " deg is not a finite number"};
  if (known_bias && !known_bias_usable(*known_bias))
    return NotComputed{"known bias " + number_text(known_bias->bias_dph) + " +- " +
                       number_text(known_bias->bias_se_dph) + " deg/h is not usable"};
  const double phi = site.latitude_deg * kRadPerDeg;
  const double horizontal_dph = kEarthRateDph * std::cos(phi);
  if (!(horizontal_dph > kMinProjection * kEarthRateDph))
    return NotComputed{"at a pole the horizontal Earth rate that shows the axis vanishes"};
  const auto w = weighted_projection(points);
  if (!w) return NotComputed{w.error()};
  HorizontalAxisResult r;
  r.fit = projection_from(*w);
  // alpha_IA - alpha_n = psi_z - theta0 - alpha_n (positions.hpp).
  r.in_plane_misalignment_rad =
      wrap_deg(site.table_zero_azimuth_deg - r.fit.phase_deg - nominal_axis_table_deg) * kRadPerDeg;
  r.in_plane_misalignment_se_rad = r.fit.phase_se_deg * kRadPerDeg;
  r.amplitude_ratio = r.fit.amplitude_dph / horizontal_dph;
  r.amplitude_ratio_se = r.fit.amplitude_se_dph / horizontal_dph;
  // The phase, so the heading, means something only for an amplitude resolved (A > 3 SE(A), as
  // for the vertical axis) and near Omega cos phi: the ratio is cos(delta_v)(1 + SF error), so a
  // ratio under kMinHorizontalRatio (an elevation over 60 deg) beyond its 3 SE is an axis that is
  // not horizontal as configured, or a wrong latitude.
  if (!r.fit.amplitude_resolved ||
      r.amplitude_ratio + 3 * r.amplitude_ratio_se < kMinHorizontalRatio ||
      r.amplitude_ratio - 3 * r.amplitude_ratio_se > kMaxHorizontalRatio)
    return NotComputed{"the Earth rate's projection is " + number_text(r.amplitude_ratio) + " +- " +
                       number_text(r.amplitude_ratio_se) +
                       " of the horizontal Earth rate, not about 1: the input axis is not "
                       "horizontal as configured (or the latitude is wrong); no heading"};
  r.bias_if_level_dph = r.fit.constant_dph;
  r.bias_if_level_se_dph = r.fit.constant_se_dph;
  if (known_bias) add_out_of_plane(kEarthRateDph * std::sin(phi), *known_bias, r);
  return r;
}

}  // namespace station::compensation
