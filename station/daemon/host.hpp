// The one host of a rig: its devices, its store and its clock, in one of two states. Idle
// (between runs, `serve`): each look reads the rig once (read_rig), judges it (rig_faults),
// drives the lamps and records each change. Running: a StartPlan (start_run, the one start) is
// carried out to its end by the sequencer's 1 Hz loop, which reads the rig once a tick through
// the same read_rig. `run --config`, `serve`, `run --sim` and `replay` differ only in what they
// give it: a clock (monotonic, simulated, replayed), the rig's transports (real, simulators,
// recordings) and the sequencer's hooks.
#pragma once

#include <functional>

#include "drivers/common/clock.hpp"
#include "station/config/config.hpp"
#include "station/daemon/idle_watch.hpp"
#include "station/daemon/rig.hpp"
#include "station/daemon/run_start.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/store/store.hpp"

namespace station {

class Host {
 public:
  /// Nothing is read or written here. `on_event` is told each idle event (may be empty).
  Host(const StationConfig& config, Rig& rig, Store& store, drivers::Clock& clock,
       std::function<void(const RunEvent&)> on_event = {});

  /// Rules 1-5 of run_start.hpp on this host's store.
  StartPlan start(const StartRequest& request) { return start_run(store_, config_, request); }
  /// Running: the plan's run (new or resumed) to its end, on the plan's configuration (the
  /// run's gyros). The plan decides where a resumed simulation replays to; `options` carries
  /// the caller's hooks (`plan` must outlive the call).
  RunOutcome run(const StartPlan& plan, SequencerOptions options);
  /// Idle: one look at the rig (idle_watch.hpp).
  IdleReading look() { return idle_.look(); }

  const StationConfig& config() const { return config_; }
  Store& store() { return store_; }
  drivers::Clock& clock() { return clock_; }

 private:
  const StationConfig& config_;
  Rig& rig_;
  Store& store_;
  drivers::Clock& clock_;
  IdleWatch idle_;
};

}  // namespace station
