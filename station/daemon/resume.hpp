// What every sample of a run means (slots, pulse weights, axes, latitude, reference temperature,
// bin length), stored with the run and compared when a start would continue it (run_start.hpp).
#pragma once

#include <optional>
#include <string>

#include "station/config/config.hpp"
#include "station/store/store.hpp"

namespace station {

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

}  // namespace station
