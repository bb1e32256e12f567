// Asking a running station what it sees: GET /api/status of the daemon that serves its API
// (`serve`, or `run --http`), as `station probe` does when the rig is in use and its devices
// must not be touched.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace station::http {

/// The daemon's answer, or why there was none.
struct StatusAnswer {
  std::string url;                       ///< "http://127.0.0.1:8080/api/status"
  std::optional<nlohmann::json> status;  ///< the parsed answer (schemas/api.md, GET /api/status)
  std::string error;                     ///< set when status is empty: refused, timed out, HTTP 401
};

/// The address a client on this machine reaches a service listening at `listen` (HOST:PORT) on:
/// a wildcard host (0.0.0.0, ::, empty) is reached on loopback. Throws InputError when `listen`
/// is not HOST:PORT.
std::pair<std::string, int> reach_address(const std::string& listen);

/// GET /api/status from the station listening at `listen`: the whole exchange within
/// `timeout_s` (a dripping or endless answer is cut there), an answer over 1 MiB refused, an
/// answer that is not a JSON object refused. Never throws for a station that is not there.
StatusAnswer fetch_status(const std::string& listen, double timeout_s);

}  // namespace station::http
