// What the daemon commands (run, serve) share before and after a run: process locks, the peek
// for an unfinished run.
#pragma once

#include <spdlog/common.h>

#include <cstdint>
#include <string>
#include <vector>

#include "station/common/process_lock.hpp"
#include "station/config/config.hpp"
#include "station/store/store.hpp"

namespace station {

/// Signal `sig` calls `handler` (which only sets atomics).
void on_signal(int sig, void (*handler)(int));
/// SIGTERM and SIGINT call `handler`: the daemon ends cleanly.
void on_stop_signals(void (*handler)(int));
/// The daemon commands' logging: `console_level` on the console, the rotating `log_file` if
/// given, and the journal's own fields when systemd connected stdout to it (JOURNAL_STREAM).
void setup_daemon_logging(spdlog::level::level_enum console_level, const std::string& log_file);
/// One daemon per database (and, on a real rig, per device): held until the process ends.
std::vector<ProcessLock> lock_db_and_devices(const std::string& db, const StationConfig* config);
/// The device locks alone (lock_db_and_devices without the database), as `probe` takes them
/// while it reads the devices; throws InputError naming the holder when one is held.
std::vector<ProcessLock> lock_devices(const StationConfig& config);

}  // namespace station
