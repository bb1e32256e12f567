// A run's acceptance figures (issue 36), from what it stored: each acceptance step's
// acceptance_point events (the windows the runner measured, what the table did) and the 1 Hz
// samples in those windows, through the maths of compensation/scale_factor.hpp,
// positions.hpp and turn_on.hpp.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "compensation/positions.hpp"
#include "compensation/scale_factor.hpp"
#include "compensation/turn_on.hpp"
#include "station/store/store.hpp"

namespace station {

/// One rate ladder of one serial (one plateau).
struct LadderFigures {
  int step_index = 0;
  std::string label;
  double temp_c = 0;  ///< sensor A where the slope was taken (slope_temp_c: the fast points'), C
  int points = 0;     ///< points the schedule has
  int missing = 0;    ///< points without a measured window (a kill or a hold across it)
  compensation::Computed<compensation::LadderResult> fit{compensation::NotComputed{"not analysed"}};
  /// The measured points the fit took (with each one's temperature), in the schedule's order.
  std::vector<compensation::LadderPoint> measured;
};

/// One set of positions of one serial.
struct PositionFigures {
  int step_index = 0;
  std::string label;
  double temp_c = 0;
  int points = 0, excluded = 0;
  std::vector<double> angles_deg;  ///< the table angle of each point the fit took, in its order
  /// The input axis up (the slot's axis "up"): its tilt from the table's axis.
  compensation::Computed<compensation::VerticalAxisResult> fit{
      compensation::NotComputed{"not analysed"}};
  /// The input axis horizontal (north, south, east, west, heading:DEG): its nominal heading at
  /// table angle 0, deg clockwise from north, and its figures (`fit` is then left unset: see
  /// positions_projection).
  std::optional<double> nominal_heading_deg;
  compensation::Computed<compensation::HorizontalAxisResult> horizontal{
      compensation::NotComputed{"not analysed"}};
};

/// Sign conventions of a horizontal axis's positions, stated once. The table angle theta is
/// counterclockwise seen from above (right-handed about up: the sense of a positive table rate,
/// which an up axis senses positively); a heading is clockwise from north (a [[slot]] axis
/// heading:DEG). The axis at heading H at theta = 0 points at H - theta at theta, so the
/// analysis takes the table's zero mark at north (psi_z = 0) and the axis at table angle -H
/// (compensation/positions.hpp). The heading error is the true heading less the nominal one,
/// positive clockwise: the negated in-plane misalignment (counterclockwise) of positions.hpp.
inline double heading_error_rad(const compensation::HorizontalAxisResult& r) {
  return -r.in_plane_misalignment_rad;
}

/// The fitted projection of a positions step, whichever the mounting; nullptr when its figures
/// were not computed, `why` then saying why.
const compensation::ProjectionFit* positions_projection(const PositionFigures& p,
                                                        std::string* why = nullptr);

/// The bias a positions step's projection is drawn less of, deg/h: the vertical axis's bias, or
/// for a horizontal axis the fit's constant (its bias if level: bias_if_level_dph).
double positions_bias_dph(const PositionFigures& p);

/// One turn-on's bias in kTurnOnBinS bins from its power-up: what its warm-up was judged on.
struct TurnOnCurve {
  std::vector<double> t_s;       ///< bin centre, s since power-up
  std::vector<double> bias_dph;  ///< bin mean rate minus the Earth rate along the axis, deg/h
};

/// One power_cycles step of one serial.
struct TurnOnStep {
  int step_index = 0;
  std::string label;
  double temp_c = 0;  ///< sensor A's mean over the powered windows, C (NaN: none)
  compensation::Computed<compensation::TurnOnResult> result{
      compensation::NotComputed{"not analysed"}};
  std::vector<TurnOnCurve> curves;  ///< the analysed turn-ons' bins, in result's order
  double band_dph = 0;              ///< the warm-up band used
};

/// Everything one serial's acceptance steps gave.
struct SerialAcceptance {
  std::string serial;
  double earth_rate_dph = 0;  ///< the Earth rate along its input axis (the run's slot), deg/h
  std::vector<LadderFigures> ladders;
  /// The scale factor against temperature over the ladders (two or more plateaus).
  std::optional<compensation::Computed<compensation::ScaleFactorTemperatureFit>> sf_vs_temp;
  std::vector<PositionFigures> positions;
  /// The first power_cycles step's figures (what the report, the store and the fleet carry).
  std::optional<compensation::Computed<compensation::TurnOnResult>> turn_on;
  std::vector<TurnOnCurve> turn_on_curves;  ///< the analysed turn-ons' bins, in turn_on's order
  double turn_on_band_dph = 0;              ///< the warm-up band used
  /// Every power_cycles step's figures, in the protocol's order: each step on its own (a second
  /// block is often at another temperature: pooling its biases would add a temperature effect
  /// to the repeatability); every one is judged.
  std::vector<TurnOnStep> turn_on_steps;
  std::string positions_note;  ///< why positions were not analysed (an axis down)
};

/// Bin width of a turn-on's bias series, s: long enough that a bin's white noise (ARW 0.003
/// deg/sqrt(h): 0.023 deg/h) is below a warm-up transient of a few hundredths.
inline constexpr double kTurnOnBinS = 60.0;

/// The acceptance figures of every serial of run `run_id`; empty when its protocol has no
/// acceptance step. `ref_temp_c`: the temperature the scale factor is reported at.
std::vector<SerialAcceptance> run_acceptance(Store& store, std::int64_t run_id,
                                             double ref_temp_c = 25.0);

}  // namespace station
