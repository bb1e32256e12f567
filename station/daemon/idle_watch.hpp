// Between runs (`station serve`): the rig stays connected and watched once a second. Tower lamp
// amber (idle), red while an e-stop is pressed, the door is open or the chamber alarms; each
// change of such a condition is one event (no run). Nothing moves: no chamber or table command
// is sent while idle.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "station/daemon/outputs.hpp"
#include "station/daemon/rig.hpp"
#include "station/daemon/rig_reading.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/store/store.hpp"

namespace station {

/// One idle look at the rig: the reading (rig_reading.hpp) and what rig_faults() found in it.
struct IdleReading {
  RigReading in;
  std::string fault;      ///< empty: every device answered and nothing is alarming
  std::string fault_key;  ///< the same as stable names (device: error kind), for change detection
  std::string storage_error;  ///< this look's event could not be stored (empty: stored or none)
};

/// Watches an idle rig. Not thread-safe (the serve loop's thread).
class IdleWatch {
 public:
  /// `on_event` is told each event stored (the live page's event list); may be empty.
  IdleWatch(Rig& rig, Store& store, std::function<void(const RunEvent&)> on_event = {})
      : rig_(rig), store_(store), on_event_(std::move(on_event)), outputs_(rig.gpio.get(), 0) {}
  /// Reads every device once (read_rig), drives the lamps, stores an event when the faults
  /// (rig_faults) change.
  IdleReading look();
  /// Forget the lamps written (a run drove them meanwhile): the next look writes them again.
  void run_ended() { outputs_.forget(); }

 private:
  /// Stores (and tells) the event of a change of the faults; a store failure goes into
  /// `r.storage_error`.
  void note_change(IdleReading& r);

  Rig& rig_;
  Store& store_;
  std::function<void(const RunEvent&)> on_event_;
  std::string last_key_;  ///< what is wrong, without the messages' changing details
  RigOutputs outputs_;    ///< the lamps (idle_outputs); the relays are the runs' to drive
};

}  // namespace station
