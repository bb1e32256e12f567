// The session's own metadata against what the replay re-derives from it: session.toml's
// station, latitude, protocol name, slots and resolved_json are what its config and protocol
// say (schemas/session.md).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "station/config/config.hpp"
#include "station/config/protocol.hpp"

namespace station {

/// The first key of `session_toml_path` that is not what `config` and `protocol` (read from the
/// same file) make of it: {"at": {"file", "key"}, "quantity", "recorded", "replayed"}; nullopt
/// when every key agrees.
std::optional<nlohmann::json> header_difference(const std::string& session_toml_path,
                                                const StationConfig& config,
                                                const Protocol& protocol);

}  // namespace station
