// Test helper: the options of a quiet simulated run of tests/data/short_cycle.toml (about 2.2 h
// of simulated time, seconds of wall time) in a fresh database.
#pragma once

#include <string>

#include "station/sim/sim_run.hpp"

namespace station::testing_support {

inline SimRunOptions short_cycle_run(const std::string& db, int gyros) {
  SimRunOptions o;
  o.db_path = db;
  o.protocol = std::string(STATION_TEST_DATA_DIR) + "/short_cycle.toml";
  o.progress = false;
  o.fresh = true;
  o.gyros = gyros;
  return o;
}

}  // namespace station::testing_support
