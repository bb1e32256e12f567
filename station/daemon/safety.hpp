// The safety layer no protocol can override: chamber commands clamped to the station's limits;
// interlock, e-stop or a device reading out of limits puts the chamber in a safe hold and stops the
// turntable.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "drivers/chamber/chamber.hpp"
#include "station/config/config.hpp"
#include "station/config/protocol.hpp"

namespace station {

/// Limits enforcement and the safe-hold state. No I/O: the sequencer applies what it returns.
class Safety {
 public:
  explicit Safety(const LimitsConfig& limits) : limits_(limits) {}

  /// `cmd` with setpoint and ramp clamped to the limits; a note per clamp in `notes`.
  drivers::ChamberCommand clamp(drivers::ChamberCommand cmd, std::vector<std::string>& notes) const;

  /// A copy of `p` with every setpoint and ramp inside the limits; a note per change.
  Protocol clamp_protocol(const Protocol& p, std::vector<std::string>& notes) const;

  /// What the chamber reported this tick that lies outside the limits, one phrase each (read-back
  /// setpoint outside the setpoint limits; air beyond them by more than the air margin). Empty
  /// when all is inside or nothing was read.
  std::vector<std::string> judge(const std::optional<drivers::ChamberState>& chamber) const;

  /// Feeds the interlock/e-stop inputs and the readings judged out of limits; returns a message
  /// when the safe-hold state changes ("enter: ..." or "clear: ...").
  std::optional<std::string> update(bool interlock_open, bool estop_pressed,
                                    const std::vector<std::string>& out_of_limits = {});
  /// True while readings out of limits hold the rig (a fault: tower lamp red).
  bool limits_fault() const { return limits_fault_; }
  /// True while the rig must stay in safe hold.
  bool holding() const { return holding_; }
  /// The command that holds the chamber where it is (setpoint = air, step), clamped.
  drivers::ChamberCommand hold_command(double air_c) const;

 private:
  LimitsConfig limits_;
  bool holding_ = false;
  bool interlock_open_ = false, estop_ = false, limits_fault_ = false;
};

}  // namespace station
