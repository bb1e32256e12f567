// `station probe`: commissioning check of a rig. Reads every configured device once and reports
// what it got, each failure as a typed error line; no device failure is fatal.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "station/config/config.hpp"
#include "station/daemon/rig.hpp"

namespace station {

/// Builds the rig of `config`, reads chamber, turntable, counter boards (one SYNC) and GPIO inputs
/// once each and prints the result to `out` (text, or one JSON object when `json`). Returns 0 when
/// every device answered, 1 when any failed. Blocks at most the sum of the devices' timeouts.
/// Throws InputError / std::invalid_argument only for configuration problems.
int probe_rig(const StationConfig& config, const RigOptions& options, std::ostream& out, bool json);

/// Probes every device of `rig` once, as probe_rig does (reads only, nothing moves), and returns
/// one line per device that did not answer: "CONFIG: DEVICE WHERE unreachable: ERROR". The
/// counter boards keep no baseline from the probe. Blocks at most the devices' timeouts.
std::vector<std::string> unreachable_devices(const StationConfig& config, Rig& rig);

}  // namespace station
