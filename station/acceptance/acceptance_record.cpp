// A run's acceptance figures judged and stored.
#include "station/acceptance/acceptance_record.hpp"

#include "station/acceptance/acceptance_json.hpp"
#include "station/acceptance/acceptance_run.hpp"
#include "station/acceptance/acceptance_verdict.hpp"
#include "station/common/logging.hpp"
#include "station/store/acceptance_results.hpp"

namespace station {

nlohmann::json judged_acceptance(Store& store, std::int64_t run_id,
                                 const std::map<std::string, PartLimits>& part_limits) {
  nlohmann::json serials = acceptance_json(run_acceptance(store, run_id));
  judge_acceptance(serials, part_limits);
  return serials;
}

nlohmann::json record_acceptance(Store& store, std::int64_t run_id,
                                 const std::map<std::string, PartLimits>& part_limits) {
  nlohmann::json serials = judged_acceptance(store, run_id, part_limits);
  std::vector<AcceptanceRow> rows;
  for (const auto& s : serials) rows.push_back(acceptance_row(run_id, s));
  replace_acceptance_rows(store, run_id, rows);
  return serials;
}

bool record_acceptance_at_end(Store& store, std::int64_t run_id,
                              const std::map<std::string, PartLimits>& part_limits) noexcept {
  try {
    record_acceptance(store, run_id, part_limits);
    return true;
  } catch (const std::exception& e) {
    // Derived figures: the run's record stands without them; `station fit --acceptance`
    // computes them again.
    log("seq")->error("run={} acceptance figures not stored: {}", run_id, e.what());
  } catch (...) {
    log("seq")->error("run={} acceptance figures not stored: unknown error", run_id);
  }
  return false;
}

}  // namespace station
