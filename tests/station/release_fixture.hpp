// Test helper: a database with a calibrated and a verification run of the same simulated gyros
// (`run --sim --verify` on the short cycle): run 1 fitted and released, run 2 verified.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "station/sim/sim_run.hpp"
#include "tests/station/temp_db.hpp"

namespace station::testing_support {

struct CalibratedDb {
  std::string path;
  std::int64_t calibration_run = 0, verification_run = 0;
  nlohmann::json report;  ///< run_simulated_with_verification's
};

inline CalibratedDb calibrated_db(const std::string& name, int gyros = 2) {
  SimRunOptions o;
  o.db_path = fresh_db(name);
  o.protocol = std::string(STATION_TEST_DATA_DIR) + "/short_cycle.toml";
  o.progress = false;
  o.fresh = true;
  o.gyros = gyros;
  o.seed = 5;
  CalibratedDb c;
  c.path = o.db_path;
  c.report = run_simulated_with_verification(o);
  c.calibration_run = c.report["calibration_run"]["run_id"].get<std::int64_t>();
  c.verification_run = c.report["run_id"].get<std::int64_t>();
  return c;
}

}  // namespace station::testing_support
