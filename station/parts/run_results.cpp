// A run's results per slot (run_results.hpp).
#include "station/parts/run_results.hpp"

#include <fmt/format.h>

#include "station/parts/judged_fit.hpp"
#include "station/store/fit_json.hpp"
#include "station/store/run_fits.hpp"

namespace station {

nlohmann::json slot_result_json(Store& store, std::int64_t run_id, const RunSlot& slot) {
  nlohmann::json j{{"slot", slot.slot}, {"serial", slot.serial}};
  const auto fit = own_fit_of_run(store, slot.serial, run_id);  // the report's, the API's
  if (!fit) {
    j["error"] = "no fit for this run";
    return j;
  }
  j["fit_id"] = fit->id;
  j["model"] = fit->terms;
  j["fitted"] = coefficients_json(fit->fit);
  j["units"] = units_json(fit->fit);
  j["std_errors"] = std_errors_json(fit->fit);
  j["std_errors_ols"] = std_errors_ols_json(fit->fit);
  j["bins"] = fit->fit.n_points;
  j["std_before_dph"] = fit->eval.std_before_dph;
  j["std_after_dph"] = fit->eval.std_after_dph;
  j["std_ratio"] = std_ratio_json(fit->eval);  // null when undefined
  const auto verdict = stored_verdict(store, fit->id);
  j["part_number"] = verdict ? nlohmann::json(verdict->part_number) : nlohmann::json(nullptr);
  j["verdict"] = verdict ? verdict_json(*verdict) : nlohmann::json(nullptr);
  j["verdict_text"] = slot_verdict_text(verdict, slot.slot);
  return j;
}

std::string slot_verdict_text(const std::optional<Verdict>& verdict, int slot) {
  return verdict ? verdict_text(verdict)
                 : fmt::format("no part limits (slot {} names no part)", slot + 1);
}

nlohmann::json run_results_json(Store& store, std::int64_t run_id) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& s : store.run_slots(run_id)) out.push_back(slot_result_json(store, run_id, s));
  return out;
}

}  // namespace station
