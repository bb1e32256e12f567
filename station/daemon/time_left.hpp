// How long a run has left, by its protocol's steps: the one rule behind "step 4/5, 3 h 10 min
// left" on the terminal, in the log and in systemd's status line (cli/progress_display).
#pragma once

#include <optional>
#include <string>

#include "station/config/protocol.hpp"

namespace station {

/// Where a run stands, as the time-left rule reads it.
struct StepPosition {
  int step_index = 0;                   ///< the current step (== steps: the protocol has ended)
  double in_step_s = 0;                 ///< run time since the step started (the stored start)
  std::optional<double> start_c;        ///< the run's start temperature (to_start), deg C
  std::optional<double> ramp_point_c;   ///< the setpoint a ramp last commanded, deg C
  std::optional<double> ramp_target_c;  ///< where the ramp goes (the step's target), deg C
};

/// The run's time left, s: the current step's remainder plus every later step's nominal
/// duration (Protocol::nominal_step_durations_s). The remainder of a ramp is the distance from
/// its last commanded setpoint to its target at its rate (so a ramp restarted after a safe hold
/// counts from where it was held); of a soak or hold, its duration less the time in the step,
/// not below 0 (counted from the stored step start: a resumed run knows its elapsed time); of
/// any other step, 0. Waits for the air are not counted (they are not nominal): the estimate
/// does not go down while a step overruns. Empty when a duration is unknown (a ramp from the
/// start temperature before it was read).
std::optional<double> time_left_s(const Protocol& p, const StepPosition& at);

/// "3 h 10 min left", "25 min left", "under 1 min left" (minutes rounded up).
std::string time_left_text(double left_s);

}  // namespace station
