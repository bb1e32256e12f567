// Between runs (`station serve`): the rig stays connected and watched once a second. Tower lamp
// amber (idle), red while an e-stop is pressed, the door is open or the chamber alarms; each
// change of such a condition is one event (no run). Nothing moves: no chamber or table command
// is sent while idle.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "station/daemon/rig.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/store/store.hpp"

namespace station {

/// One idle look at the rig.
struct IdleReading {
  std::optional<drivers::ChamberState> chamber;
  std::optional<drivers::TurntableState> table;
  std::optional<bool> door_closed, estop_pressed;
  std::vector<IoError> io_errors;
  std::string fault;      ///< empty: every device answered and nothing is alarming
  std::string fault_key;  ///< the same as stable names (device: error kind), for change detection
  std::string storage_error;  ///< this look's event could not be stored (empty: stored or none)
};

/// Watches an idle rig. Not thread-safe (the serve loop's thread).
class IdleWatch {
 public:
  /// `on_event` is told each event stored (the live page's event list); may be empty.
  IdleWatch(Rig& rig, Store& store, std::function<void(const RunEvent&)> on_event = {})
      : rig_(rig), store_(store), on_event_(std::move(on_event)) {}
  /// Reads every device once, drives the lamps, stores an event when the fault text changes.
  IdleReading look();
  /// Forget the lamps written (a run drove them meanwhile): the next look writes them again.
  void run_ended() { lamps_written_ = false; }

 private:
  void drive_lamps(bool red);

  Rig& rig_;
  Store& store_;
  std::function<void(const RunEvent&)> on_event_;
  std::string last_key_;  ///< what is wrong, without the messages' changing details
  bool lamps_written_ = false;
  bool red_ = false;
};

}  // namespace station
