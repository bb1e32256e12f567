// The end summary of a run, one formatter for `run --sim` and `run --config`: each serial's
// coefficients with their standard errors, the std of the bias before and after compensation and
// their ratio, the model, the verdict (or which slot names no part), and where the report is.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "station/parts/part_file.hpp"
#include "station/store/store.hpp"

namespace station {

/// The summary as text. `report`: {"run_id", "state", "gyros": [parts/run_results'
/// slot_result_json, with "true" {B0, k1, k0} for a simulated gyro], "report" (how to get the
/// report: a command or a link; absent: not said)} with either "sim_s" and "wall_s" (a
/// simulation) or "t_s" and "ticks" (a rig); `run --sim --verify` adds "calibration_run",
/// "releases" and "verifications" (sim/sim_run.hpp).
std::string run_summary_text(const nlohmann::json& report);

/// The report object of a run on a rig, read back from the store: run_id, state, t_s, ticks,
/// gyros (run_results_json) and "report": the `station report` command for its database.
/// With acceptance steps, "acceptance": each serial's figures (acceptance/acceptance_json),
/// judged against `part_limits` (by serial) where its part has acceptance limits.
nlohmann::json rig_run_summary(Store& store, std::int64_t run_id, std::string_view state,
                               double t_s, std::int64_t ticks, const std::string& db_path,
                               const std::map<std::string, PartLimits>& part_limits = {});

/// The command that writes run `run_id`'s report from `db_path` (shell-quoted where needed).
std::string report_command(const std::string& db_path, std::int64_t run_id);

}  // namespace station
