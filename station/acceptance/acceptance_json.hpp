// A run's acceptance figures as JSON (the end summary, `--json`) and as the summary's text.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "station/acceptance/acceptance_run.hpp"

namespace station {

/// [{"serial", "ladders": [...], "sf_vs_temp", "positions": [...], "turn_on", ...}]: every
/// figure with its standard error; a figure that could not be computed is {"ok": false,
/// "error": why}. A caller may add "true" (a simulated gyro's truth) to a serial's object.
nlohmann::json acceptance_json(const std::vector<SerialAcceptance>& serials);

/// The summary's acceptance section: per serial each figure with its error, against "true"
/// where the object has it. Empty for an empty array.
std::string acceptance_text(const nlohmann::json& serials);

/// A serial's "verdict" (judge_acceptance) in words: "PASS, 13 limits", or "FAIL: " and each
/// failure (the end summary, `fit`, `history`).
std::string acceptance_verdict_text(const nlohmann::json& verdict);

}  // namespace station
