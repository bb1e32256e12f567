// The session's header from the configuration and protocol, its result from the store.
#include "station/session/session_recording.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <chrono>

#include "station/daemon/resume.hpp"
#include "station/session/session_digest.hpp"
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
  // The run has ended: what the daemon does after it (the GPIO bank releasing its outputs as
  // the rig is torn down) is no part of the session, and the digest below is final.
  recorder_.pause(true);
  recorder_.flush();
  store.flush();
  write_session_result(store, run_id, dir_);
  const auto run = store.find_run(run_id);
  append_session_end(dir_, {run ? std::string(to_string(run->state)) : std::string("unknown"),
                            run ? run->last_tick_s.value_or(0.0) : 0.0});
  // Last: the digest covers session.toml (with its [end]), the logs and result.json.
  write_session_digest(dir_);
}

}  // namespace station
