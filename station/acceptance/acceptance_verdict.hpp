// The acceptance figures judged against a part's limits ([part."PN".acceptance], issue 36).
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "station/parts/part_file.hpp"

namespace station {

/// Adds "verdict" {"part", "pass", "checked", "failed": ["nonlinearity 120.3 ppm FS at 'scale
/// factor, hot' above 100", ...]} to each serial of `serials` (acceptance_json) whose part has
/// acceptance limits. A figure within its limit passes; a limit whose figure the run did not
/// measure (not computed, or no such step) fails, named.
void judge_acceptance(nlohmann::json& serials, const std::map<std::string, PartLimits>& by_serial);

}  // namespace station
