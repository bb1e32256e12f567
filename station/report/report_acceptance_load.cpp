// The acceptance pages' data from the store: station/acceptance's figures with the turn-ons'
// bins and the positions' angles they were computed from.
#include "station/report/report_acceptance.hpp"

namespace station::report {

std::vector<SerialAcceptanceReport> load_acceptance(Store& store, const RunRecord& run) {
  std::vector<SerialAcceptanceReport> out;
  if (run.protocol_text.empty()) return out;  // a run stored without its protocol
  for (auto& f : run_acceptance(store, run.id)) {
    SerialAcceptanceReport s;
    // The bins the analysis judged each turn-on's warm-up on, and the angles its positions fit
    // took: drawn as the analysis saw them (acceptance_run.cpp), never binned a second time.
    if (f.turn_on && *f.turn_on) s.warmups = f.turn_on_curves;
    for (const auto& p : f.positions) s.position_angles_deg.push_back(p.angles_deg);
    s.figures = std::move(f);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace station::report
