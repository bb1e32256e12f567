// The safety layer no protocol can override: chamber commands clamped to the station's limits;
// interlock or e-stop puts the chamber in a safe hold and stops the turntable.
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

  /// Feeds the interlock/e-stop inputs; returns a message when the safe-hold state changes
  /// ("enter: ..." or "clear: ...").
  std::optional<std::string> update(bool interlock_open, bool estop_pressed);
  /// True while the rig must stay in safe hold.
  bool holding() const { return holding_; }
  /// The command that holds the chamber where it is (setpoint = air, step), clamped.
  drivers::ChamberCommand hold_command(double air_c) const;

 private:
  LimitsConfig limits_;
  bool holding_ = false;
  bool interlock_open_ = false, estop_ = false;
};

}  // namespace station
