// Another master's setpoint (issue 34 point 3): each tick the chamber's setpoint as read back is
// compared with the one the station last had accepted; a difference beyond the register's
// resolution is someone else's (the front panel, another Modbus master): one event, and the
// station's value written again or the run held ([chamber] on_foreign_setpoint). No I/O.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "drivers/chamber/chamber.hpp"
#include "station/store/events.hpp"

namespace station {

/// What to do about a foreign setpoint ([chamber] on_foreign_setpoint).
enum class ForeignSetpoint { restore, hold };

/// "restore" / "hold" to the value; std::nullopt for anything else.
std::optional<ForeignSetpoint> parse_foreign_setpoint(std::string_view text);
const char* to_string(ForeignSetpoint f);

/// One tick's verdict on the chamber's setpoint.
struct SetpointNews {
  std::vector<EventNote> events;    ///< setpoint_foreign when one appears, _end when it goes
  std::optional<double> restore_c;  ///< write this setpoint again (restore, while foreign)
};

/// The station's setpoint against the chamber's read-back. Not thread-safe.
class SetpointWatch {
 public:
  explicit SetpointWatch(ForeignSetpoint action = ForeignSetpoint::restore) : action_(action) {}
  /// The chamber accepted `setpoint_c` (a protocol step, a hold, a restore), deg C.
  void commanded(double setpoint_c) { commanded_c_ = setpoint_c; }
  /// One reading (none: no news; the first, before any command, is the reference);
  /// `resolution_c` the register's step
  /// (Chamber::setpoint_resolution_c): a read-back within it is the commanded value.
  SetpointNews observe(const std::optional<drivers::ChamberState>& chamber, double resolution_c);
  /// A foreign setpoint is in force now.
  bool foreign() const { return foreign_; }
  ForeignSetpoint action() const { return action_; }

 private:
  ForeignSetpoint action_;
  std::optional<double> commanded_c_;
  bool foreign_ = false;
};

}  // namespace station
