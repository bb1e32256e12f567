// A serial's acceptance verdict beside its thermal one (acceptance_beside.hpp).
#include "station/cli/acceptance_beside.hpp"

#include <fmt/format.h>

#include "station/acceptance/acceptance_json.hpp"
#include "station/store/acceptance_results.hpp"

namespace station {

nlohmann::json acceptance_beside_json(Store& store, const std::string& serial,
                                      const std::vector<std::int64_t>& runs) {
  const auto row = newest_acceptance_row(store, serial, runs);
  if (!row) return nullptr;
  return {{"run_id", row->run_id},
          {"part_number", row->part_number ? nlohmann::json(*row->part_number) : nullptr},
          {"verdict", row->figures.value("verdict", nlohmann::json())},
          {"sf_pulse_per_arcsec",
           row->sf_pulse_per_arcsec ? nlohmann::json(*row->sf_pulse_per_arcsec) : nullptr}};
}

std::string acceptance_beside_text(const nlohmann::json& a) {
  if (a.is_null()) return "";
  const std::string verdict = a["verdict"].is_null()
                                  ? std::string("not judged (no acceptance limits)")
                                  : acceptance_verdict_text(a["verdict"]);
  return fmt::format("  acceptance verdict (run {}{}): {}\n", a["run_id"].get<std::int64_t>(),
                     a["part_number"].is_null() ? "" : ", " + a["part_number"].get<std::string>(),
                     verdict);
}

}  // namespace station
