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
//     It keeps its own gyros (run_gyros.hpp): a start that gives none continues with the stored
//     serials and parts, one that gives others is refused with one line naming each (in rule 2).
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
#include "station/daemon/run_gyros.hpp"
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
  /// The gyros given at start (--slot, the API's slots), checked by gyro_problems; slots not
  /// given take the configuration's defaults (a new run) or the run's own (a resume).
  std::vector<SlotGyro> gyros;
};

/// What the start does.
struct StartPlan {
  std::optional<RunRecord> resume;  ///< the run to continue; none: a new run
  Protocol protocol;                ///< the protocol to run (a resumed run's own)
  /// A resumed simulation recomputes its ticks up to here without storing them.
  std::optional<double> replay_until_t_s;
  std::vector<std::string> warnings;  ///< logged by start_run; for the caller to show as well
  /// The run's configuration: the rig's, with the run's gyros on its slots (the sequencer's).
  StationConfig config;
};

/// Whether `db` exists and holds a run to resume (read-only peek: nothing is created or written).
bool has_unfinished_run(const std::string& db);

/// Rule 4 before anything is written: throws InputError with the request's rig problems when a
/// new run would start (--new, or no unfinished run in `db`). Call before opening the store, so
/// a refused start leaves no database file.
void refuse_broken_rig(const std::string& db, const StartRequest& request);

/// The gyro check before anything is written (gyro_problems; the part file: `parts_path`, else
/// the configuration's): throws InputError::lines. Returns `config` with the gyros a new run
/// would have (for the start check's messages), or `config` itself when a run would resume.
StationConfig refuse_bad_gyros(const std::string& db, const StationConfig& config,
                               const StartRequest& request, const std::string& parts_path);

/// The one start (rules 1-5 above) on an open store. Throws InputError when refused.
StartPlan start_run(Store& store, const StationConfig& config, const StartRequest& request);

}  // namespace station
