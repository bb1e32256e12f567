// Positions test (issue 36): the table holds still at angles theta_i, the gyro's output at each
// is fitted against the Earth rate's projection on its input axis (IA); out come the bias and
// the IA's misalignment. Pure maths: spans in, result structs out.
//
// Frames and conventions (stated, so a caller can map a table onto them):
//   - Local level East-North-Up; the Earth rate there is Omega (0, cos phi, sin phi), phi the
//     geodetic latitude, Omega = kEarthRateDph (earth_rate.hpp; Titterton & Weston, Strapdown
//     Inertial Navigation Technology, 2nd ed., eq. 3.41).
//   - The table's axis points up. The table angle theta is right-handed about it
//     (counterclockwise seen from above: the sense of a positive table rate about up). A table
//     turning the other way: negate the angles.
//   - psi_z, the table zero's azimuth: the azimuth (clockwise from north, deg) of the table's
//     zero mark at theta = 0. A direction fixed on the table at angle alpha (counterclockwise
//     from the zero mark) then points at azimuth psi_z - alpha - theta.
//   - A unit axis at azimuth psi and elevation e senses Omega (cos phi cos e cos psi +
//     sin phi sin e) (dot product with the Earth rate above).
//
// Fit (both mountings): y_i = c + a cos theta_i + b sin theta_i by weighted least squares
// (weights 1/se_i^2, covariance rule of acceptance.hpp), rewritten y = c + A cos(theta - theta0)
// with A = sqrt(a^2 + b^2), theta0 = atan2(b, a). SEs by the delta method: A with gradient
// (a, b)/A, theta0 with (-b, a)/A^2. Near A = 0 the delta method fails (the amplitude's
// estimate is Rice distributed, biased up, and the phase is meaningless): amplitude_resolved
// says A > 3 SE(A); below that treat the misalignment as an upper bound, not a value.
//
// IA nominally vertical (along the table's axis), tilted by delta towards table angle alpha_t:
//   y = B + Omega sin phi cos delta + Omega cos phi sin delta cos(theta - theta0),
//   theta0 = psi_z - alpha_t. Hence sin delta = A / (Omega cos phi) (exact; small angle:
//   delta = A / (Omega cos phi)), the tilt's direction on the table alpha_t = psi_z - theta0,
//   and B = c - Omega sin phi cos delta (dB/dA = tan phi tan delta for the delta method).
//   Not at a pole (cos phi = 0: the horizontal Earth rate that reveals the tilt vanishes).
//
// IA nominally horizontal at table angle alpha_n, actually at alpha_IA, tilted out of the
// table's plane (towards up) by delta_v:
//   y = B + Omega cos phi cos delta_v cos(theta - theta0) + Omega sin phi sin delta_v,
//   theta0 = psi_z - alpha_IA. In-plane misalignment = alpha_IA - alpha_n = psi_z - theta0 -
//   alpha_n (wrapped to +-180 deg; positive: the IA turned counterclockwise seen from above).
//   The constant c = B + Omega sin phi sin delta_v mixes the bias and the out-of-plane tilt:
//   they separate only with a known bias (the axis-vertical positions, or a bias known
//   otherwise): sin delta_v = (c - B) / (Omega sin phi). Without one, bias_if_level_dph = c
//   is the bias assuming delta_v = 0. The amplitude gives cos delta_v only to second order
//   (and times (1 + scale factor error)): amplitude_ratio = A / (Omega cos phi) is reported as
//   a check, not used for delta_v.
//
// Sources: input-axis alignment and multi-position (Earth-rate) tests are items of IEEE Std
// 647-2006 and IEEE Std 952-1997 per their public abstracts; the clause texts were not
// available, so no clause is cited. The method — one least-squares fit of the performance model
// (bias plus the Earth rate's projection through the axis's nonorthogonality to the table) to
// fixed positions, with the coefficients' standard errors from the fit — is that of the USAF
// Central Inertial Guidance Test Facility's standard test (DTIC AD0655068, abstract verified).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "compensation/acceptance.hpp"

namespace station::compensation {

/// The gyro at rest at one table angle.
struct PositionPoint {
  double table_angle_deg = 0;  ///< theta, right-handed about the table's (up) axis
  double output_dph = 0;       ///< the mean output, Earth rate included, deg/h
  double output_se_dph = 0;    ///< its standard error, deg/h (> 0)
};

/// Where the table is.
struct PositionSite {
  double latitude_deg = 0;            ///< geodetic latitude phi, deg
  double table_zero_azimuth_deg = 0;  ///< psi_z: azimuth of the zero mark at theta = 0, deg
};

/// y = c + A cos(theta - theta0), fitted to the positions.
struct ProjectionFit {
  double constant_dph = 0, constant_se_dph = 0;    ///< c
  double amplitude_dph = 0, amplitude_se_dph = 0;  ///< A
  double phase_deg = 0, phase_se_deg = 0;          ///< theta0 in (-180, 180]
  bool amplitude_resolved = false;                 ///< A > 3 SE(A) (delta method valid)
  std::vector<double> residuals_dph;               ///< per position, in the input's order
  std::size_t positions = 0;
  std::size_t dof = 0;  ///< positions - 3
  double chi2 = 0;
  double se_scale = 1;  ///< acceptance.hpp's chi2/dof factor
};

/// IA nominally along the table's axis.
struct VerticalAxisResult {
  ProjectionFit fit;
  double tilt_rad = 0, tilt_se_rad = 0;              ///< delta = asin(A / (Omega cos phi))
  double tilt_small_rad = 0, tilt_small_se_rad = 0;  ///< A / (Omega cos phi)
  double tilt_direction_table_deg = 0;               ///< alpha_t = psi_z - theta0, wrapped to +-180
  double tilt_direction_se_deg = 0;                  ///< = SE(theta0)
  double bias_dph = 0, bias_se_dph = 0;              ///< c - Omega sin phi cos delta
};

/// A bias known from elsewhere (the axis-vertical positions, a thermal calibration).
struct KnownBias {
  double bias_dph = 0;
  double bias_se_dph = 0;  ///< >= 0
};

/// IA nominally horizontal.
struct HorizontalAxisResult {
  ProjectionFit fit;
  double in_plane_misalignment_rad = 0;  ///< alpha_IA - alpha_n
  double in_plane_misalignment_se_rad = 0;
  double amplitude_ratio = 0;  ///< A / (Omega cos phi): cos delta_v (1 + SF error), a check
  double amplitude_ratio_se = 0;
  double bias_if_level_dph = 0;  ///< c: the bias if delta_v = 0
  double bias_if_level_se_dph = 0;
  /// delta_v = asin((c - B) / (Omega sin phi)): only with a KnownBias, and not at the equator.
  std::optional<double> out_of_plane_rad;
  std::optional<double> out_of_plane_se_rad;
};

/// The least number of distinct positions (three unknowns).
inline constexpr std::size_t kMinPositions = 3;

/// Fits y = c + A cos(theta - theta0). NotComputed on fewer than kMinPositions points, angles
/// that do not separate cos and sin (fewer than 3 distinct angles mod 360), a value not finite,
/// an angle beyond +-360 deg, an output beyond kMaxAbsRateDph, or an SE <= 0.
Computed<ProjectionFit> fit_earth_rate_projection(std::span<const PositionPoint> points);

/// IA nominally vertical. NotComputed as fit_earth_rate_projection, or at a pole, or when
/// A > Omega cos phi (no tilt explains it: a wrong latitude or a mounting that is not vertical).
Computed<VerticalAxisResult> analyze_positions_axis_vertical(std::span<const PositionPoint> points,
                                                             const PositionSite& site);

/// IA nominally horizontal at table angle `nominal_axis_table_deg` (counterclockwise from the
/// zero mark). `known_bias` separates bias and out-of-plane tilt. NotComputed as
/// fit_earth_rate_projection, or at a pole.
Computed<HorizontalAxisResult> analyze_positions_axis_horizontal(
    std::span<const PositionPoint> points, const PositionSite& site, double nominal_axis_table_deg,
    std::optional<KnownBias> known_bias = std::nullopt);

}  // namespace station::compensation
