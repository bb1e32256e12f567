// `run --sim --verify`: calibrate, release, and verify the released calibrations on a second run
// of the same simulated gyros with independent noise (issue 21; README, "Verifying on an
// independent run").
#include <fmt/format.h>

#include "station/parts/judged_fit.hpp"
#include "station/release/releases.hpp"
#include "station/release/verification.hpp"
#include "station/sim/sim_run.hpp"

namespace station {
namespace {

constexpr const char* kReleasedBy = "station run --sim --verify";

/// Releases the fit of each gyro of `run_id` whose verdict allows it; returns what happened.
nlohmann::json release_run_fits(Store& store, const nlohmann::json& report, std::int64_t run_id) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& g : report["gyros"]) {
    const std::string serial = g["serial"].get<std::string>();
    const auto fit = store.latest_fit_of_run(serial, run_id);
    if (!fit) continue;
    try {
      const ReleaseRow r = release_fit(
          store, {fit->id, kReleasedBy, fmt::format("simulated calibration run {}", run_id), {}});
      out.push_back({{"serial", serial}, {"fit_id", fit->id}, {"released", true}});
      (void)r;
    } catch (const ReleaseRefused& e) {
      out.push_back(
          {{"serial", serial}, {"fit_id", fit->id}, {"released", false}, {"why", e.what()}});
    }
  }
  return out;
}

nlohmann::json verify_released(Store& store, const nlohmann::json& releases, std::int64_t run_id) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : releases) {
    if (!r["released"].get<bool>()) continue;
    const auto fit = store.find_fit(r["fit_id"].get<std::int64_t>());
    const std::string serial = fit->serial;
    try {
      const auto limits = limits_for(store, serial, {run_id}, {});
      VerificationResult v = verify_fit(store, *fit, run_id, limits);
      save_verification(store, v);
      out.push_back(verification_json(v));
    } catch (const InputError& e) {  // e.g. the second run was stopped before its first bin
      out.push_back({{"serial", serial}, {"fit_id", fit->id}, {"error", e.what()}});
    }
  }
  return out;
}

}  // namespace

nlohmann::json run_simulated_with_verification(const SimRunOptions& o) {
  const nlohmann::json first = run_simulated(o);
  const auto first_id = first["run_id"].get<std::int64_t>();
  const std::string db = o.db_path.empty() ? "station-sim.db" : o.db_path;
  nlohmann::json releases;
  {
    Store store(db, OpenMode::existing);
    releases = release_run_fits(store, first, first_id);
  }
  if (o.stop != nullptr && o.stop->load()) return first;
  SimRunOptions second = o;
  second.noise_run = o.noise_run + 1;
  second.fresh = true;  // the verification run is a new run, never a resume of the first
  second.record_dir.clear();
  second.record_can_path.clear();
  second.faults.clear();
  nlohmann::json report = run_simulated(second);
  Store store(db, OpenMode::existing);
  report["calibration_run"] = first;
  report["releases"] = releases;
  report["verifications"] = verify_released(store, releases, report["run_id"].get<std::int64_t>());
  return report;
}

}  // namespace station
