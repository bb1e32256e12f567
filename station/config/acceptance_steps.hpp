// The acceptance steps of a protocol (issue 36): rate_ladder, positions, power_cycles. Each is a
// schedule of points fixed by the step alone, as a function of the time since the step started,
// so a resumed run continues it exactly (as a ramp does) and the analysis reads the same
// windows the runner measured.
#pragma once

#include <string>
#include <vector>

#include "station/config/protocol.hpp"

namespace station {

class TomlView;  // station/config/toml_reader.hpp: toml++ only where a file is read

/// rate_ladder, positions or power_cycles.
bool is_acceptance_step(StepKind k);

/// positions: the table is at its angle within this, deg (the runner's check over a window); two
/// angles of one step closer than this (mod 360) are one angle and refused at parse.
inline constexpr double kAngleToleranceDeg = 0.1;

/// One point of an acceptance step; times from the step's start, s.
struct AcceptancePoint {
  int index = 0;
  /// rate_ladder: the rate demand, deg/s (signed); positions: the angle demand, deg;
  /// power_cycles: the turn-on's number from 1.
  double demand = 0;
  double start_s = 0;    ///< demand sent (power_cycles: power off)
  double measure_s = 0;  ///< measuring starts (after travel and settling; power_cycles: power on)
  double end_s = 0;      ///< measuring ends; the next point starts here
};

/// The step's points in order. rate_ladder: for each magnitude r as given, +r then -r; the
/// table's travel to a demand is |change| / accel_dps2 (it starts at rest), then settle_s, then
/// dwell_s. positions: settle_s, then dwell_s, per angle (the nominal schedule: a table not in
/// position when settle_s is over is waited for, and settles settle_s from its arrival,
/// station/daemon/acceptance_runner.cpp). power_cycles: off_s unpowered, then dwell_s powered,
/// per cycle. Empty for other kinds.
std::vector<AcceptancePoint> acceptance_schedule(const Step& s);
/// The step's whole time, s: its last point's end, and for a ladder the table's travel back to
/// rest and settle_s.
double acceptance_duration_s(const Step& s);

/// Reads the keys of an acceptance step into `s` (its kind already set); throws InputError
/// naming the key ("FILE:LINE: key 'step[4].rates_dps': entry 2: 4000 is outside 0..1000 deg/s").
/// Two ladder rates closer than the step's rate_tolerance_dps (the table's read-back cannot tell
/// them apart), or two angles closer than kAngleToleranceDeg mod 360, are refused, naming both.
void read_acceptance_step(const TomlView& v, Step& s);
/// A rate_ladder or positions step leaves the table turning or unlocked at an angle: a
/// lock_turntable step must follow it before the record window opens or the protocol ends.
/// Throws InputError naming the step.
void check_tables_locked(const std::vector<Step>& steps, const std::string& path);

}  // namespace station
