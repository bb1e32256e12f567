// spdlog setup: shared sinks, one named logger per subsystem.
#include "station/common/logging.hpp"

#include <spdlog/sinks/rotating_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/sinks/systemd_sink.h>

#include <mutex>
#include <vector>

namespace station {
namespace {

std::mutex g_mutex;
std::vector<spdlog::sink_ptr> g_sinks;

}  // namespace

void setup_logging(const LogOptions& options) {
  std::lock_guard lock(g_mutex);
  g_sinks.clear();
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  console->set_level(options.console_level);
  g_sinks.push_back(console);
  if (!options.file.empty()) {
    auto file = std::make_shared<spdlog::sinks::rotating_file_sink_mt>(options.file, 10 << 20, 5);
    file->set_level(spdlog::level::debug);
    g_sinks.push_back(file);
  }
  if (options.journald) g_sinks.push_back(std::make_shared<spdlog::sinks::systemd_sink_mt>());
  spdlog::drop_all();
  for (const char* name : {"seq", "chamber", "table", "can", "gpio", "db", "safety"}) {
    auto logger = std::make_shared<spdlog::logger>(name, g_sinks.begin(), g_sinks.end());
    logger->set_level(spdlog::level::debug);
    logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ [%n] %v");
    spdlog::register_logger(logger);
  }
}

std::shared_ptr<spdlog::logger> log(const std::string& subsystem) {
  auto logger = spdlog::get(subsystem);
  if (logger) return logger;
  std::lock_guard lock(g_mutex);
  if (g_sinks.empty()) g_sinks.push_back(std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  logger = std::make_shared<spdlog::logger>(subsystem, g_sinks.begin(), g_sinks.end());
  spdlog::register_logger(logger);
  return logger;
}

}  // namespace station
