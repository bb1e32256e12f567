// Choosing whether a start continues a run a killed daemon left 'running': only the same rig
// (same slots) continues, with the protocol stored with the run; anything else is refused or,
// with --new, marks the old run 'aborted'.
#pragma once

#include <optional>
#include <string>

#include "station/config/config.hpp"
#include "station/config/protocol.hpp"
#include "station/store/store.hpp"

namespace station {

/// What a start should do.
struct ResumeDecision {
  std::optional<RunRecord> run;      ///< the run to continue, if any
  std::optional<Protocol> protocol;  ///< its stored protocol (continue with this one)
};

/// Why `run` cannot be continued on `config` (different slots), or empty when it can.
std::string resume_mismatch(Store& store, const RunRecord& run, const StationConfig& config);

/// The unfinished run of `store`, if it can continue on `config`. With `fresh`, or when
/// `abort_mismatch` and it does not match, the old run is marked 'aborted' (with an event) and
/// none is returned; otherwise a mismatch throws InputError naming the difference.
ResumeDecision decide_resume(Store& store, const StationConfig& config, bool fresh,
                             bool abort_mismatch);

}  // namespace station
