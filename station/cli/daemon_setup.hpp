// What the daemon commands (run, serve) share before and after a run: process locks, the peek
// for an unfinished run, the verdict lines.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "station/common/process_lock.hpp"
#include "station/config/config.hpp"
#include "station/store/store.hpp"

namespace station {

/// SIGTERM and SIGINT call `handler` (which only sets atomics): the daemon ends cleanly.
void on_stop_signals(void (*handler)(int));
/// One daemon per database (and, on a real rig, per device): held until the process ends.
std::vector<ProcessLock> lock_db_and_devices(const std::string& db, const StationConfig* config);
/// Whether `db` exists and holds a run to resume (read-only peek: nothing is created or written).
bool has_unfinished_run(const std::string& db);
/// Each slot's fit and verdict of run `run_id`, one line per slot on stdout.
void print_verdicts(Store& store, std::int64_t run_id);

}  // namespace station
