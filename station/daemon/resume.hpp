// Choosing whether a start continues a run a killed daemon left 'running': only a run whose
// samples would mean the same (same slots, pulse weights, axes, latitude, reference temperature,
// bin length) continues, with the protocol stored with the run; anything else is refused or,
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

/// The run's slots from the config: node, serial, axis, pulse weight and the Earth rate along
/// the axis at the station's latitude (compensation/earth_rate.hpp, WGS-84).
std::vector<RunSlot> run_slots_of(const StationConfig& config);

/// What gives every sample of a run on `config` its meaning, as JSON text: latitude, reference
/// temperature, bin length and per slot node, serial, pulse weight, axis and Earth rate. Stored
/// with the run (runs.resolved_json) and compared on resume.
std::string resolved_meaning_json(const StationConfig& config);

/// Why `run` cannot be continued on `config`, as one line naming each difference
/// ("slots/1/pulse_weight_arcsec 1.5 -> 3"), or empty when it can.
std::string resume_mismatch(Store& store, const RunRecord& run, const StationConfig& config);

/// The unfinished run of `store`, if it can continue on `config`. With `fresh`, or when
/// `abort_mismatch` and it does not match, the old run is marked 'aborted' (with an event) and
/// none is returned; otherwise a mismatch throws InputError naming the difference.
ResumeDecision decide_resume(Store& store, const StationConfig& config, bool fresh,
                             bool abort_mismatch);

}  // namespace station
