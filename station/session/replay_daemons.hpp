// The recorded daemons of a session replayed through the one host (daemon/host.hpp): the first
// makes the run, each restarted one ([[resume]] in session.toml) continues it by the one start
// rule (daemon/run_start.hpp), with every device answered from the session's logs.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/session/session_digest.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_replay.hpp"
#include "station/store/store.hpp"

namespace station {

/// What session.toml says the run was.
struct RecordedSession {
  StationConfig config;
  Protocol protocol;
  std::optional<std::int64_t> sim_seed;
  SessionEnd end;
  std::string started_utc;  ///< when the run started ("2026-11-23T06:00:00Z")
};

/// Replays the session in `dir` into `store`; returns the run's id, or 0 when a divergence ended
/// it (then `report` says where: same = false, first_difference, notes, ticks). Throws
/// InputError when the recording cannot be replayed (a resume without its keys, a recording
/// that starts mid-run, a run that ended before its recorded kill).
/// `on_tick` (optional) is told each tick's t_s before it is replayed.
/// The logs are read once each through `reads` (verified as they are read).
std::int64_t replay_daemons(const std::string& dir, SessionReads& reads,
                            const RecordedSession& session, Store& store, ReplayReport& report,
                            const std::function<void(double t_s)>& on_tick = {});

}  // namespace station
