// The session's header from the configuration and protocol, its result from the store.
#include "station/session/session_recording.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <chrono>

#include "station/daemon/resume.hpp"
#include "station/session/session_files.hpp"

#ifndef STATION_VERSION
#define STATION_VERSION "dev"
#endif

namespace station {

void SessionRecording::start(const StationConfig& config, const Protocol& protocol, bool simulated,
                             std::optional<std::int64_t> sim_seed) {
  SessionHeader h;
  h.station = config.name;
  h.software_version = STATION_VERSION;
  h.started_utc =
      fmt::format("{:%Y-%m-%dT%H:%M:%SZ}",
                  std::chrono::floor<std::chrono::seconds>(std::chrono::system_clock::now()));
  h.latitude_deg = config.latitude_deg;
  h.simulated = simulated;
  h.sim_seed = sim_seed;
  h.config_text = config.text;
  h.resolved_json = resolved_meaning_json(config);
  h.protocol_name = protocol.name;
  h.protocol_text = protocol.text;
  h.slots = run_slots_of(config);
  write_session_header(dir_, h);
}

void SessionRecording::finish(Store& store, std::int64_t run_id) {
  recorder_.flush();
  store.flush();
  write_session_result(store, run_id, dir_);
}

}  // namespace station
