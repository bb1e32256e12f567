// `station replay DIR`: a recorded session (schemas/session.md) through the unchanged daemon —
// sequencer, safety, protocol runner, store, binning, fit — with replay transports for every
// device on a virtual clock (no sockets, no wall-clock waits, no original database), then
// compared with the session's result.json sample by sample, bin by bin, event by event, fit by
// fit.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "station/store/store.hpp"

namespace station {

struct ReplayOptions {
  std::string dir;  ///< the session directory
  std::string db;   ///< keep the replayed database here (must not exist); empty: a temp file
  double rtol = 0;  ///< relative tolerance per value (0: exact)
  double atol = 0;  ///< absolute tolerance per value (0: exact)
  /// Check the files against digest.txt first (a mismatch: differs, naming the file and line).
  /// Off only in tests that change a recording on purpose to see what the daemon makes of it.
  bool verify = true;
  /// Say it is a replay on stderr: the replayed daemon's log lines stamped "replayed, recorded
  /// TIME" (the recording's time, not now) and a progress line at each tenth of the run
  /// (replay_narration.hpp). `station replay` sets it; the comparison never sees it.
  bool narrate = false;
};

/// What a replay found.
struct ReplayReport {
  bool same = true;
  std::int64_t ticks = 0, bins = 0, events = 0, fits = 0;  ///< in the replay
  nlohmann::json first_difference;                         ///< null when same
  nlohmann::json max_abs_difference;  ///< quantity -> largest |replayed - recorded|
  std::vector<std::string> notes;     ///< the short report, one line each

  /// {"verdict": "same"|"differs", "ticks", "bins", "first_difference", "max_abs_difference"}.
  nlohmann::json json() const;
};

/// Replays `o.dir`. A bad session (unreadable, malformed, unknown format version) throws
/// InputError naming the file and line; a divergence (the daemon asked what the recording does
/// not hold) is a difference, reported with the tick, the device and both requests.
ReplayReport replay_session(const ReplayOptions& o);

class LogLineReader;

/// Compares the recorded result.json at `result_path` (or its .gz), read by `result` as it is
/// compared, with run `run_id` of `store` (the replayed run): tick by tick, then bins, events and
/// fits. Throws InputError naming the file when it is not a result.json of this format version.
ReplayReport compare_with_store(const std::string& result_path, LogLineReader& result, Store& store,
                                std::int64_t run_id, double rtol, double atol);

}  // namespace station
