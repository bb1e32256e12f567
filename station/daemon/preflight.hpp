// Before a run moves anything: every configured device must answer once (chamber, turntable,
// every slot's counter board, the GPIO chip). A rig that cannot be reached is refused, not run
// with every sample flagged.
#pragma once

#include <string>
#include <vector>

#include "station/config/config.hpp"
#include "station/daemon/rig.hpp"

namespace station {

/// Connects and reads each device of `rig` once (bounded by the devices' timeouts); one line
/// "DEVICE ENDPOINT: what failed" per device that did not answer, empty when all did.
std::vector<std::string> preflight(Rig& rig, const StationConfig& config);

}  // namespace station
