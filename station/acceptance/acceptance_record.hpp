// A run's acceptance figures judged and stored (migration 12): one code path for the run's end,
// `station fit --acceptance` and the end summary, so the stored rows are exactly what
// run_acceptance and judge_acceptance give.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "station/parts/part_file.hpp"
#include "station/store/store.hpp"

namespace station {

/// acceptance_json(run_acceptance(run_id)) judged against `part_limits` (by serial): an array
/// of the serials' objects, empty when the run's protocol has no acceptance step.
nlohmann::json judged_acceptance(Store& store, std::int64_t run_id,
                                 const std::map<std::string, PartLimits>& part_limits);

/// judged_acceptance stored as the run's rows (replacing earlier ones); returns it. Throws what
/// the computation or the store throws, nothing stored then.
nlohmann::json record_acceptance(Store& store, std::int64_t run_id,
                                 const std::map<std::string, PartLimits>& part_limits);

/// record_acceptance at a run's end: a failure is logged (logger "seq", error) and swallowed, so
/// the run still ends with its samples, bins and fits. Returns whether the figures were stored.
bool record_acceptance_at_end(Store& store, std::int64_t run_id,
                              const std::map<std::string, PartLimits>& part_limits) noexcept;

}  // namespace station
