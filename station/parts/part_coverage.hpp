// Which gyros of a run a part file judges: a slot that names no part gets no limits and no
// verdict, which a person who gave a part file (--parts, [station] parts) did not ask for
// silently (issue 35): the daemon commands say so when the run starts.
#pragma once

#include <string>
#include <vector>

#include "station/config/config.hpp"

namespace station {

/// One line per slot of `config` that names no part while a part file is in effect
/// (`parts_path`, else the configuration's [station] parts): "PARTS: slot N (node K, serial S)
/// names no part: no part limits, no verdict (...)". Empty when every slot names one, or when
/// no part file is in effect. No I/O.
std::vector<std::string> slots_without_part(const StationConfig& config,
                                            const std::string& parts_path);

/// slots_without_part's lines as warnings in the `seq` log (stderr and the log file).
void warn_slots_without_part(const StationConfig& config, const std::string& parts_path);

}  // namespace station
