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
  /// The station is about to write `setpoint_c`, deg C: until the write is acknowledged or
  /// refused, a read-back of this value is the station's too (its reply may be lost).
  void trying(double setpoint_c) { tried_c_ = setpoint_c; }
  /// The chamber accepted `setpoint_c` (a protocol step, a hold, a restore), deg C.
  void commanded(double setpoint_c) {
    commanded_c_ = setpoint_c;
    tried_c_.reset();
  }
  /// The write tried failed; `outcome_unknown` when it may have reached the chamber (a timeout, a
  /// reply cut off or garbled, a link lost mid-exchange): a read-back of the value tried is then
  /// taken as commanded, with no event. A refusal (or a write never sent) forgets it.
  void failed(bool outcome_unknown) {
    if (!outcome_unknown) tried_c_.reset();
  }
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
  std::optional<double> tried_c_;  ///< written, its outcome not known yet
  bool foreign_ = false;
};

}  // namespace station
