// Shared daemon set-up.
#include "station/daemon/daemon_setup.hpp"

#include <fmt/format.h>

#include <csignal>
#include <cstdlib>

#include "station/common/logging.hpp"
#include "station/daemon/device_identity.hpp"

namespace station {

void on_signal(int sig, void (*handler)(int)) {
  struct sigaction sa {};
  sa.sa_handler = handler;
  sigemptyset(&sa.sa_mask);
  sigaction(sig, &sa, nullptr);
}

void on_stop_signals(void (*handler)(int)) {
  on_signal(SIGTERM, handler);
  on_signal(SIGINT, handler);
}

void setup_daemon_logging(spdlog::level::level_enum console_level, const std::string& log_file) {
  LogOptions lo;
  lo.console_level = console_level;
  lo.file = log_file;
  lo.journald = std::getenv("JOURNAL_STREAM") != nullptr;
  setup_logging(lo);
}

/// One daemon per database (and, on a real rig, per device): held until the process ends.
std::vector<ProcessLock> lock_db_and_devices(const std::string& db, const StationConfig* config) {
  std::vector<ProcessLock> locks;
  locks.push_back(ProcessLock::acquire_database(db));
  if (config == nullptr) return locks;
  for (auto& l : lock_devices(*config)) locks.push_back(std::move(l));
  return locks;
}

std::vector<ProcessLock> lock_devices(const StationConfig& config) {
  std::vector<ProcessLock> locks;
  std::vector<std::string> endpoints{config.chamber.endpoint, config.can_transport};
  if (config.turntable) endpoints.push_back(config.turntable->endpoint);
  // Keyed on what each endpoint reaches, not on its spelling (device_identity.hpp).
  for (const auto& e : endpoints) {
    for (const auto& id : device_identities(e)) {
      const std::string what =
          id == e ? fmt::format("device {}", e) : fmt::format("device {} (as {})", e, id);
      locks.push_back(ProcessLock::acquire(device_lock_path(id), what));
    }
  }
  return locks;
}

}  // namespace station
