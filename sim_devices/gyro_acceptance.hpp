// What a simulated RLG has beyond its thermal bias (issue 36): scale-factor errors, turn-on bias
// and warm-up, and how its input axis sits on the table. Pure functions of the truth; no I/O.
#pragma once

#include <cstdint>

namespace station::sim {

/// How the gyro's input axis is mounted on the table (the table axis is the local vertical, and
/// positive table rotation is right-handed about up).
enum class InputAxis : std::uint8_t {
  vertical,    ///< along the table axis, pointing up: it senses the table's rotation
  horizontal,  ///< in the table's plane: it senses the table only through its misalignment
};

/// The acceptance-test truth of one simulated gyro. All zero (the default) is the gyro before
/// issue 36: nominal scale factor, no turn-on bias or warm-up, input axis exactly up.
/// Scale-factor terms follow IEEE Std 647-2006 (RLG test procedure) definitions: scale factor
/// error, its temperature sensitivity, nonlinearity (ppm of full scale) and asymmetry.
struct AcceptanceTruth {
  double sf_error_ppm = 0;     ///< scale factor error at ref_temp_c (TrueCoefficients), ppm
  double sf_tc_ppm_per_c = 0;  ///< its temperature coefficient on sensor A's dT, ppm/degC
  /// Nonlinearity, ppm of full scale: the output deviates by nonlinearity_ppm * P3(x) ppm of
  /// full scale, x = input rate / full_scale_dps, P3(x) = (5x^3 - 3x)/2 (Legendre). P3 is odd and
  /// orthogonal to 1 and x over [-1, 1]: on a dense, uniform ladder from -FS to FS the
  /// least-squares line keeps the scale factor (1 + sf_error) and the largest residual is
  /// |nonlinearity_ppm|, at +-FS. On another ladder use scale_factor_error_ppm for the truth.
  double nonlinearity_ppm = 0;
  double asymmetry_ppm = 0;         ///< positive-rate SF minus negative-rate SF, ppm (+-half each)
  double full_scale_dps = 300;      ///< full scale of the nonlinearity, deg/s
  double turn_on_sigma_dph = 0;     ///< sigma of the bias drawn anew at each power-up, deg/h
  double warmup_amplitude_dph = 0;  ///< warm-up transient at power-up, deg/h (decays exp(-t/tau))
  double warmup_tau_s = 300;        ///< its time constant, s
  /// vertical: tilt of the input axis from the table axis; horizontal: its elevation out of the
  /// table's plane; rad.
  double misalignment_rad = 0;
  /// vertical only: the table angle at which the tilt leans towards north, deg.
  double misalignment_azimuth_deg = 0;
  /// horizontal only: the table angle at which the input axis points north, deg. The table
  /// turns counterclockwise seen from above for a positive angle, so the axis's heading
  /// (clockwise from north) at table angle theta is north_at_table_deg - theta: this is also its
  /// true heading at table angle 0.
  double north_at_table_deg = 0;
  /// horizontal only: the heading the slot states for the axis at table angle 0 (its [[slot]]
  /// axis), deg clockwise from north; north_at_table_deg - this is the heading error.
  double nominal_heading_deg = 0;
  InputAxis input_axis = InputAxis::vertical;
};

/// The same gyro mounted with its input axis horizontal at `nominal_heading_deg` (clockwise
/// from north at table angle 0): its drawn misalignment (magnitude m = misalignment_rad towards
/// the drawn misalignment_azimuth_deg a) becomes a heading error m cos(a) and an elevation out
/// of the table's plane m sin(a), so the axis is m from where the slot says, as drawn.
AcceptanceTruth mounted_horizontal(AcceptanceTruth a, double nominal_heading_deg);

/// horizontal: the true heading less the nominal one, wrapped to +-180 deg, in rad (positive:
/// the axis turned clockwise seen from above); 0 for a vertical axis.
double heading_error_rad(const AcceptanceTruth& a);

/// One power-up of a simulated gyro: when (its own clock, s) and the turn-on bias drawn, deg/h.
struct PowerUp {
  double t_s = 0;
  double turn_on_bias_dph = 0;
};

/// The relative scale-factor error at input-axis rate `input_rate_dps` and dT = T_A - T_ref
/// (`dt_c`), ppm: sf_error + sf_tc*dT + nonlinearity*(5x^2-3)/2 + sign(rate)*asymmetry/2
/// (IEEE 647 terms; the nonlinearity as in AcceptanceTruth). The output is (1 + 1e-6*this)*rate.
double scale_factor_error_ppm(const AcceptanceTruth& a, double input_rate_dps, double dt_c);

/// The part of the table's rotation along the input axis (the dot product of the input axis with
/// the table axis): cos(misalignment) vertical, sin(misalignment) horizontal.
double table_coupling(const AcceptanceTruth& a);

/// The Earth rate along the input axis, deg/h, averaged while the table turns at a steady rate
/// from `from_deg` to `to_deg` (the same angle: the table at rest there). `up_dph`, `north_dph`:
/// the Earth rate's vertical and north components (W sin(lat), W cos(lat): Titterton & Weston,
/// eq. 3.41). Vertical: up*cos(d) + north*sin(d)*cos(theta - theta0); horizontal:
/// north*cos(d)*cos(theta - psi) + up*sin(d), with d the misalignment.
double earth_rate_along_input_dph(const AcceptanceTruth& a, double up_dph, double north_dph,
                                  double from_deg, double to_deg);

/// The warm-up transient amplitude*exp(-t/tau) averaged over [from_s, to_s] after power-up, deg/h.
double warmup_mean_dph(const AcceptanceTruth& a, double from_s, double to_s);

/// Distinct, realistic acceptance truth for gyro `index` of a world seeded with `seed` (its own
/// random stream: the thermal coefficients and the noise stay what they were): SF error
/// +-(10..60) ppm, TC +-(1..5) ppm/C, nonlinearity +-(10..50) ppm, asymmetry +-(10..30) ppm,
/// turn-on sigma 0.004..0.006 deg/h, warm-up +-(0.016..0.024) deg/h over tau 240..360 s,
/// misalignment 0.5..2 mrad towards a random table angle; input axis vertical.
AcceptanceTruth sim_acceptance_truth(std::uint64_t seed, int index);

}  // namespace station::sim
