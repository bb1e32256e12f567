// The one way a run starts. `run --config`, `serve`, `run --sim` and `replay` each describe what
// they ask for (a StartRequest: the protocol, --new, the simulation's seed, what their start
// check found wrong with the rig) and start_run() decides, by one rule, whether a run a killed
// daemon left 'running' continues or a new one is made:
//
//  1. --new: the unfinished run is marked 'aborted' (an event says why) and a new run starts.
//  2. The unfinished run continues only when every sample would mean the same (resume.hpp:
//     slots, pulse weights, axes, Earth rate, latitude, T_ref, bin length) and it was made by
//     the same source: a rig run by a rig, a simulation by the same seed. Any difference is
//     refused with one line naming each, and the hint to start anew with --new.
//  3. It continues with the protocol stored with it; a start that asked for another is told so.
//  4. Devices: a new run starts only on a rig its start check found whole; a resume goes on
//     without a missing device (its outage is recorded and it rejoins when it answers):
//     refusing would lose every other device's data as well.
//  5. Where time comes from: a rig run continues at the real elapsed time (the outage is a gap);
//     a simulation replays deterministically from t = 0 to its last stored tick.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/store/store.hpp"

namespace station {

/// What a start asks for.
struct StartRequest {
  Protocol protocol;                     ///< the protocol asked for (a resume keeps its own)
  bool fresh = false;                    ///< --new: never continue an unfinished run
  std::optional<std::int64_t> sim_seed;  ///< a simulation's seed; none for a rig or its replay
  /// What the start check found wrong with the rig, one line each (empty: whole, or no check:
  /// simulated and replayed devices are built to answer).
  std::vector<std::string> rig_problems;
  /// Only continue an unfinished run, never make one (serve at start): without one, the plan
  /// has neither a run to resume nor a protocol.
  bool resume_only = false;
};

/// What the start does.
struct StartPlan {
  std::optional<RunRecord> resume;  ///< the run to continue; none: a new run
  Protocol protocol;                ///< the protocol to run (a resumed run's own)
  /// A resumed simulation recomputes its ticks up to here without storing them.
  std::optional<double> replay_until_t_s;
  std::vector<std::string> warnings;  ///< logged by start_run; for the caller to show as well
};

/// Whether `db` exists and holds a run to resume (read-only peek: nothing is created or written).
bool has_unfinished_run(const std::string& db);

/// Rule 4 before anything is written: throws InputError with the request's rig problems when a
/// new run would start (--new, or no unfinished run in `db`). Call before opening the store, so
/// a refused start leaves no database file.
void refuse_broken_rig(const std::string& db, const StartRequest& request);

/// The one start (rules 1-5 above) on an open store. Throws InputError when refused.
StartPlan start_run(Store& store, const StationConfig& config, const StartRequest& request);

}  // namespace station
