// `station probe` while the rig is in use: the devices are another station process's (its
// device locks, daemon_setup.hpp), so probe reads none of them and asks that process instead
// (GET /api/status of the station serving at [http] listen or --http) what it sees.
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "station/http/status_client.hpp"

namespace station {

/// The exit status of a probe that asked the running station: 0 it reads every device this
/// tick, 1 a device it reads gave nothing (null in its status) or it is in state fault.
int daemon_view_status(const nlohmann::json& status);

/// Prints that the rig is in use (`holder`: the lock's refusal, naming the pid `holder_pid`)
/// and what the station at `answer.url` sees, as text or one JSON object. An answer from
/// another process than the holder (its status's "pid"), or one whose fields are not a
/// station's, is no answer. Returns the exit status: daemon_view_status, or 2 (a device in use)
/// when no usable answer came.
int print_daemon_view(const std::string& holder, const std::string& holder_pid,
                      const http::StatusAnswer& answer, std::ostream& out, bool json);

}  // namespace station
