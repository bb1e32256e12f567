// The session directory's two summary files (schemas/session.md): session.toml, what the run
// was (written when it starts), and result.json, what it produced (written when it ends).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// The session format's version (schemas/session.md, "Versions").
inline constexpr int kSessionFormatVersion = 1;

/// What session.toml holds.
struct SessionHeader {
  std::string station, software_version, started_utc;
  double latitude_deg = 0;
  bool simulated = false;
  std::optional<std::int64_t> sim_seed;
  std::string config_text;    ///< the station configuration as given (TOML)
  std::string resolved_json;  ///< what gives the samples their meaning (resolved_meaning_json)
  std::string protocol_name, protocol_text;
  std::vector<RunSlot> slots;
};

/// Writes `dir`/session.toml unless it exists (a resumed run keeps the header of its start).
/// Throws InputError naming the path when it cannot be written.
void write_session_header(const std::string& dir, const SessionHeader& header);

/// What run `run_id` stored, as result.json holds it: every tick's samples, every bin, every
/// event and every fit of the run.
nlohmann::json session_result_json(Store& store, std::int64_t run_id);

/// Writes session_result_json to `dir`/result.json (replacing it). Throws InputError.
void write_session_result(Store& store, std::int64_t run_id, const std::string& dir);

}  // namespace station
