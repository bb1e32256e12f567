// Test protocols: TOML files of steps (schemas/protocol.schema.json), parsed and checked before
// anything moves; the shipped protocols live in protocols/ and are embedded in the binary.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "station/common/input_error.hpp"

namespace station {

/// What a step does.
enum class StepKind {
  set_temperature,  ///< command setpoint (with ramp); wait until the air reaches it (optional)
  soak,             ///< wait until chamber and gyro temperatures stay within a band for a time
  hold,             ///< wait a fixed time
  record_start,     ///< open the record window
  record_stop,      ///< close the record window
  lock_turntable,   ///< position the table and engage the lock
  // The acceptance steps (issue 36; schedules in acceptance_steps.hpp). Their samples are
  // flagged kAcceptanceStep: the table turned or the gyros were switched, no thermal bin.
  rate_ladder,   ///< the table at a ladder of rates, each one way then the other (scale factor)
  positions,     ///< the table at a list of angles (Earth-rate projection, misalignment)
  power_cycles,  ///< the gyros' power off and on again (turn-on repeatability, warm-up)
};

/// One protocol step. Fields not used by its kind are ignored.
struct Step {
  StepKind kind = StepKind::hold;
  std::string label;                 ///< for logs and events
  int line = 0;                      ///< line in the protocol file
  std::optional<double> setpoint_c;  ///< set_temperature: target, deg C
  bool to_start = false;             ///< set_temperature: target is the run's start temperature
  double ramp_c_per_h = 0;           ///< set_temperature: ramp rate, 0 = step
  int ramp_line = 0;                 ///< set_temperature: line of ramp_c_per_h (or the step's)
  bool wait = true;                  ///< set_temperature: wait for the air to arrive
  double tolerance_c = 1.0;          ///< set_temperature/soak: band around the setpoint
  double duration_s = 0;             ///< soak: time stable; hold: time
  double timeout_s = 0;              ///< 0 = none; past it the step ends with a warning
  double position_deg = 0;           ///< lock_turntable
  std::vector<double> rates_dps;     ///< rate_ladder: rate magnitudes, deg/s (each +, then -)
  std::vector<double> angles_deg;    ///< positions: table angles, deg
  double settle_s = 0;    ///< acceptance: after a demand (and the table's travel), before measuring
  double dwell_s = 0;     ///< acceptance: measuring time per point (power_cycles: powered time), s
  double accel_dps2 = 0;  ///< rate_ladder: the table's acceleration limit (schedules travel), deg/s^2
  double rate_tolerance_dps = 0;  ///< rate_ladder: |read-back - demand| allowed while measuring
  int cycles = 0;                 ///< power_cycles: turn-ons
  double off_s = 0;               ///< power_cycles: unpowered time before each turn-on, s
};

/// A parsed protocol with its source text.
struct Protocol {
  std::string name, description, path, text;
  std::vector<Step> steps;
  /// Sum of the nominal durations (ramps at their rate from `start_c`), s: for progress.
  double nominal_duration_s(double start_c) const;
  /// Each step's nominal duration, s: a ramp |target - previous target| / rate (empty when an
  /// end is the start temperature and `start_c` is not known), soak and hold their duration_s,
  /// other steps (and set_temperature without a ramp) 0; waits for the air are not counted.
  std::vector<std::optional<double>> nominal_step_durations_s(std::optional<double> start_c) const;
  /// Refuses a step that would take longer than the longest step allowed (7 days): a ramp is
  /// judged over the span from the previous step's setpoint, or, where that is the run's start
  /// temperature (the first ramp, `to_start`), over the widest span within [lo_c, hi_c] (the
  /// station's setpoint limits; without them, only spans the protocol itself fixes are judged).
  /// Throws InputError "FILE:LINE: key 'step[N].ramp_c_per_h': ...".
  void check_step_times(std::optional<double> lo_c, std::optional<double> hi_c) const;
};

/// Parses protocol text labelled `path`; throws InputError ("FILE:LINE: key 'step[3].x': ...").
Protocol parse_protocol(const std::string& text, const std::string& path);
/// Reads a file, or a shipped protocol by name ("paper", "soak_ladder", "ramp_10", ...).
Protocol load_protocol(const std::string& file_or_name);
/// Names of the shipped protocols.
std::vector<std::string> builtin_protocol_names();

/// Human name of a step kind ("set_temperature", ...).
const char* to_string(StepKind k);

}  // namespace station
