// Logging: one spdlog logger per subsystem (seq, chamber, table, can, gpio, db), to the console,
// a rotating file when asked, and journald when started by systemd.
#pragma once

#include <spdlog/spdlog.h>

#include <memory>
#include <string>

namespace station {

/// Where log lines go.
struct LogOptions {
  spdlog::level::level_enum console_level = spdlog::level::info;
  std::string file;       ///< rotating log file (5 x 10 MiB); empty: none
  bool journald = false;  ///< also to the systemd journal
};

/// Creates the subsystem loggers with the given sinks (call once, before anything logs).
void setup_logging(const LogOptions& options);

/// The logger of a subsystem ("seq", "chamber", ...); created on first use if setup was skipped.
std::shared_ptr<spdlog::logger> log(const std::string& subsystem);

}  // namespace station
