// One gyro's calibrations across the fleet (`station history --pg URL --serial SN`): the same
// rows `history` reads from one station's SQLite, read from the central PostgreSQL, so the same
// statistics and drift flags (station/parts/history.hpp) apply. Ids are the fleet's (fleet_id),
// since local ids collide between stations; each row names its station.
#pragma once

#include <string>
#include <vector>

#include "station/fleet/pg.hpp"
#include "station/release/releases.hpp"
#include "station/store/serial_history.hpp"

namespace station::fleet {

struct FleetSerialHistory {
  std::vector<SerialRun> runs;       ///< oldest first (started_utc)
  std::vector<SerialFitRow> fits;    ///< oldest first (created_utc)
  std::vector<ReleaseRow> releases;  ///< oldest first; the newest is the released calibration
};

FleetSerialHistory fleet_serial_history(PgConnection& pg, const std::string& serial);

}  // namespace station::fleet
