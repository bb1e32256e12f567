// The start body's gyros (POST /api/runs, schemas/api.md): "slots": {"1": {"serial": "SN",
// "part": "PN"}, ...}, a key per slot given (from 1, the configuration's [[slot]] order).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "station/daemon/run_gyros.hpp"

namespace station::http {

/// The gyros of `body["slots"]` (none when the key is absent). On a malformed field `error` is
/// set naming it ("field 'slots/2/serial': ...") and the result is empty. The text rule for
/// identifiers applies here; which slots and parts exist the run control checks.
std::vector<SlotGyro> slots_field(const nlohmann::json& body, std::string& error);

}  // namespace station::http
