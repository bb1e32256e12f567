// What a run gave each of its gyros, as every place that shows a run's end reads it: the end
// summary of `run` (--sim and --config, cli/run_summary), the API's run (http/api_runs) and so
// the live page's results panel.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>

#include "station/parts/verdict.hpp"
#include "station/store/store.hpp"

namespace station {

/// Slot `slot`'s result in run `run_id`: {"slot", "serial", "fit_id", "model" (the fit's terms,
/// "B0+dT+gradT"), "fitted", "units", "std_errors", "std_errors_ols", "bins", "std_before_dph",
/// "std_after_dph", "std_ratio" (after/before; null when undefined), "part_number" and "verdict"
/// (null: judged against no part), "verdict_text" (slot_verdict_text)}; or {"slot", "serial",
/// "error": "no fit for this run"} when the serial's newest fit over this run is not a fit of this
/// run alone.
nlohmann::json slot_result_json(Store& store, std::int64_t run_id, const RunSlot& slot);

/// The verdict for people (verdict_text), or which slot has none: a slot judged against no
/// part names no part (a part it named without a part file, or one the file lacks, stops the
/// run before it starts), e.g. no part limits (slot 2 names no part). `slot` is the stored
/// index (RunSlot::slot, from 0); the text counts from 1, as people do.
std::string slot_verdict_text(const std::optional<Verdict>& verdict, int slot);

/// slot_result_json of every slot of run `run_id`, in slot order.
nlohmann::json run_results_json(Store& store, std::int64_t run_id);

}  // namespace station
