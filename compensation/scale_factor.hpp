// Scale factor of a gyro from a rate ladder at one temperature plateau, and its temperature
// coefficient across plateaus. Pure maths: spans in, result structs out.
//
// Units. The input rate is in arcsec/s, the output in pulses/s, so the scale factor is in
// pulses per arc-second as a ring laser gyro's is quoted. 1 deg/h = 3600 arcsec / 3600 s =
// 1 arcsec/s: a bias in arcsec/s IS a bias in deg/h, no factor needed.
//
// Model and definitions (what this file computes; the standards' texts are not public, see
// "Sources" for what could be checked):
//   Input rate of dwell i:  x_i = 3600 * table_rate_dps_i + earth_rate_dph_i   [arcsec/s]
//     (the table's read-back rate plus the Earth rate along the input axis, earth_rate.hpp).
//   Scale factor and bias:  y_i = a + K x_i + e_i, the least-squares straight line: ordinary
//     (equal-weight) least squares, its covariance L diag(se_i^2) L' from the points' standard
//     errors (acceptance.hpp, ordinary_least_squares: no chi2/dof rule, no weights from the
//     points' noisy errors). K is the scale factor (pulses/arcsec); the bias is the
//     input-equivalent intercept B = a / K [deg/h], its SE by the delta method with gradient
//     (1/K, -a/K^2).
//   Full scale:  FS = max_i |x_i| over the points used (the ladder's largest input rate);
//     full-scale output K * FS.
//   Nonlinearity: the residual r_i = y_i - a - K x_i in ppm of full-scale output,
//     r_i / (|K| FS) * 1e6; the figure is the largest |r_i| ("least-squares linearity": the
//     maximum deviation from the least-squares straight line, in parts of full scale), and
//     beside it the RMS of the r_i (the "least-squares residual" of issue 36), same unit.
//   Asymmetry: one fit with a scale factor per sign of the input and one common intercept,
//     y_i = a + K+ max(x_i, 0) + K- min(x_i, 0); asymmetry = (K+ - K-) / ((K+ + K-)/2) * 1e6
//     ppm, its SE by the delta method (gradient 4 K- / S^2, -4 K+ / S^2 times 1e6, S = K+ + K-).
//     The common intercept is the gyro's one bias: fitting each sign's line with its own
//     intercept would let a bias difference pass for asymmetry.
//   A drifting plateau: the scale factor changes with the gyro's temperature, K(T) = K(Tc) (1 +
//     TC (T - Tc) 1e-6), so a point at T_i reads K(Tc) x_i (1 + TC (T_i - Tc) 1e-6). To first
//     order the slope of the line is K at Tc = sum (x_i - xm)^2 T_i / Sxx (the fast points'
//     temperature, ladder_slope_temp_c), but the asymmetry is not: a ladder runs each rate one
//     way then the other, so +x and -x are read at temperatures apart by the drift dT between
//     them, and the asymmetry fit takes TC dT ppm for asymmetry; it is the same column |x| dT/2,
//     so a ladder alone cannot tell them apart. Given TC (the run's own fit across plateaus),
//     each point is brought to Tc first, y_i - K x_i TC (T_i - Tc) 1e-6 (K from the uncorrected
//     line: the error is second order), and TC's standard error is carried into K's and the
//     asymmetry's by the figures' (linear) sensitivity to TC. Without TC, a ladder whose points'
//     temperatures spread beyond kMaxUncorrectedDriftC has its asymmetry stated but not judged.
//   Temperature coefficient: K(T) = K0 + s (T - T_ref) fitted to the plateaus' scale factors by
//     weighted least squares (weights 1/SE(K)^2); TC = s / K0 * 1e6 ppm/degC, its SE by the
//     delta method (gradient (-s/K0^2, 1/K0) * 1e6). K0 is the scale factor at T_ref.
//
// Sources.
//   - IEEE Std 647-2006, Specification Format Guide and Test Procedure for Single-Axis Laser
//     Gyros, and IEEE Std 952-1997 (R2008), the same for interferometric fibre-optic gyros
//     (IEEE 1431-2004 for Coriolis vibratory gyros): their test procedures include the scale
//     factor over the input range with its nonlinearity and asymmetry, and the scale factor's
//     temperature sensitivity (public abstracts, standards.ieee.org/standard/647-2006.html).
//     The clause texts were NOT available to check; clause numbers are therefore not cited.
//   - The terms follow IEEE Std 528 (Inertial Sensor Terminology) as commonly summarized:
//     scale factor = ratio of a change in output to a change in input, found as the slope of
//     the least-squares straight line; scale factor asymmetry = the difference between the
//     scale factors for positive and negative inputs, relative to the scale factor (from
//     memory of the standard, not verified against its text).
//   - Nonlinearity as the deviation from a least-squares linear fit of the input/output data:
//     ECSS glossary, "scale factor non linearity" (ecss.nl, glossary_id 979, verified);
//     "least-squares linearity" as the maximum deviation from the least-squares line in parts of
//     full scale: the handbook chapter doi:10.1201/9781466564640-34, section "Linearity"
//     (a public excerpt, verified).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "compensation/acceptance.hpp"

namespace station::compensation {

/// One dwell of a rate ladder.
struct LadderPoint {
  double table_rate_dps = 0;  ///< the table's read-back rate over the dwell, deg/s
  double earth_rate_dph = 0;  ///< the Earth rate along the input axis, deg/h (earth_rate.hpp)
  double output_pps = 0;      ///< the gyro's mean output over the dwell, pulses/s
  /// Standard error of that mean, pulses/s (> 0): sample std / sqrt(n) for white noise, or the
  /// Allan deviation at the dwell's length when the noise is correlated.
  double output_se_pps = 0;
  /// False when the table did not hold the rate within its tolerance: the point is excluded
  /// and counted, and none of its values are read (they may be NaN).
  bool rate_in_tolerance = true;
  /// The gyro's temperature over the dwell, deg C; NaN (any used point's): the ladder's drift
  /// is not known and not corrected.
  double temp_c = std::numeric_limits<double>::quiet_NaN();
};

/// The temperature of a ladder's slope: sum (x_i - xm)^2 T_i / Sxx over the used points (the
/// fast points'; see "A drifting plateau"), deg C; NaN without a temperature for each.
double ladder_slope_temp_c(std::span<const LadderPoint> points);

/// The scale factor's temperature coefficient a drifting ladder is corrected with.
struct LadderTemperatureModel {
  double tc_ppm_per_c = 0;
  double tc_se_ppm_per_c = 0;  ///< carried into K's and the asymmetry's errors
};

/// The input rate of a dwell, arcsec/s (= deg/h): 3600 * table_rate_dps + earth_rate_dph.
double ladder_input_arcsec_per_s(const LadderPoint& p);

/// One used point's deviation from the least-squares line.
struct LadderResidual {
  double input_rate_dps = 0;   ///< x_i / 3600, deg/s
  double residual_ppm_fs = 0;  ///< r_i / (|K| FS) * 1e6, signed (output above the line > 0)
  double output_se_pps = 0;    ///< the point's standard error: its weight in the fit
};

/// Positive-rate and negative-rate scale factors with one common bias.
struct ScaleFactorAsymmetry {
  double sf_positive_pulse_per_arcsec = 0;
  double sf_positive_se_pulse_per_arcsec = 0;
  double sf_negative_pulse_per_arcsec = 0;
  double sf_negative_se_pulse_per_arcsec = 0;
  double asymmetry_ppm = 0;     ///< (K+ - K-) / mean(K+, K-) * 1e6
  double asymmetry_se_ppm = 0;  ///< delta method on the joint fit's covariance
  double se_scale = 1;          ///< 1: the chi2/dof rule is not applied to a ladder
  /// False: the plateau drifted beyond kMaxUncorrectedDriftC with no TC to correct it; the
  /// figure is stated, not judged (asymmetry_note says why).
  bool judged = true;
};

/// The figures of one ladder at one plateau.
struct LadderResult {
  double sf_pulse_per_arcsec = 0;     ///< K, least squares over the ladder
  double sf_se_pulse_per_arcsec = 0;  ///< its standard error
  double bias_dph = 0;                ///< a / K: the input-equivalent intercept, deg/h
  double bias_se_dph = 0;
  double nonlinearity_max_ppm_fs = 0;     ///< largest |residual|, ppm of full-scale output
  double nonlinearity_rms_ppm_fs = 0;     ///< RMS residual, ppm of full-scale output
  double full_scale_dps = 0;              ///< FS = max |x_i| / 3600, deg/s
  std::vector<LadderResidual> residuals;  ///< per used point, in the input's order
  /// Empty when the ladder lacks a rate of either sign, or the joint fit has no solution;
  /// asymmetry_note then says why.
  std::optional<ScaleFactorAsymmetry> asymmetry;
  std::string asymmetry_note;
  std::size_t points_used = 0;
  std::size_t points_excluded = 0;  ///< rate_in_tolerance == false
  std::size_t dof = 0;              ///< points_used - 2
  double chi2 = 0;                  ///< weighted residual sum of squares of the line
  double se_scale = 1;              ///< 1: the chi2/dof rule is not applied to a ladder
  double temp_c = std::numeric_limits<double>::quiet_NaN();  ///< Tc: ladder_slope_temp_c
  double drift_c = 0;            ///< the used points' temperature spread, max - min, C
  bool drift_corrected = false;  ///< the points were brought to Tc with a given TC
};

/// The largest spread of a ladder's point temperatures, C, whose asymmetry is judged without a
/// TC to correct it: at 5 ppm/C (the simulator's largest TC) it moves the asymmetry by 0.1 ppm,
/// under the simulated ladders' asymmetry SE (about 0.12 ppm).
inline constexpr double kMaxUncorrectedDriftC = 0.02;

/// The least number of used points a ladder needs (a line and one degree of freedom).
inline constexpr std::size_t kMinLadderPoints = 3;

/// The largest |K w - 1| a ladder's scale factor may have against the gyro's nominal pulse
/// weight w: an RLG's scale factor lies within a few hundred ppm of its nominal; beyond 1 % the
/// ladder did not measure the gyro (its output did not follow the table: unpowered, another
/// axis, a counter not counting). gyro_tc.h's GYRO_TC_MAX_SF_DEVIATION is the same bound.
inline constexpr double kMaxScaleFactorDeviation = 0.01;

/// The least span of plateau temperatures a temperature coefficient is fitted over, C (two
/// ladders at one temperature give none).
inline constexpr double kMinPlateauSpanC = 1.0;

/// Fits a ladder; with `tc`, the points brought to Tc first ("A drifting plateau"). NotComputed
/// with one line when fewer than kMinLadderPoints points are in tolerance, a used point has a
/// value that is not finite (or a rate beyond limits.hpp's kMaxAbsRateDph, or se <= 0), or the
/// input rates do not span a line.
Computed<LadderResult> analyze_rate_ladder(std::span<const LadderPoint> points,
                                           std::optional<LadderTemperatureModel> tc = {});

/// One plateau's scale factor (from analyze_rate_ladder) at its temperature.
struct PlateauScaleFactor {
  double temp_c = 0;                  ///< the plateau's gyro temperature, deg C
  double sf_pulse_per_arcsec = 0;     ///< K at that temperature
  double sf_se_pulse_per_arcsec = 0;  ///< its standard error (> 0)
};

/// The scale factor's temperature model K(T) = K0 + s (T - T_ref).
struct ScaleFactorTemperatureFit {
  double ref_temp_c = 0;               ///< T_ref, deg C
  double sf_ref_pulse_per_arcsec = 0;  ///< K0 = K(T_ref)
  double sf_ref_se_pulse_per_arcsec = 0;
  double slope_pulse_per_arcsec_per_c = 0;  ///< s
  double slope_se_pulse_per_arcsec_per_c = 0;
  double tc_ppm_per_c = 0;  ///< s / K0 * 1e6
  double tc_se_ppm_per_c = 0;
  std::size_t plateaus = 0;
  std::size_t dof = 0;  ///< plateaus - 2
  double chi2 = 0;
  double se_scale = 1;
};

/// Weighted least squares of K vs plateau temperature. NotComputed when fewer than two distinct
/// temperatures, a value not finite, a temperature outside limits.hpp's bounds, or an SE <= 0.
Computed<ScaleFactorTemperatureFit> fit_scale_factor_vs_temperature(
    std::span<const PlateauScaleFactor> plateaus, double ref_temp_c);

}  // namespace station::compensation
