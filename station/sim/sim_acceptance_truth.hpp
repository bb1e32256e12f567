// What a simulated gyro's acceptance figures should be (issue 36): its acceptance truth
// (sim_devices/gyro_acceptance.hpp) put through the same definitions as the measured figures.
#pragma once

#include <nlohmann/json.hpp>

#include "sim_devices/sim_world.hpp"
#include "station/config/protocol.hpp"

namespace station {

/// `serials` (acceptance_json) with each serial's "true" (scale factor at its reference
/// temperature, temperature coefficient, asymmetry, tilt, turn-on spread, warm-up time
/// constant) and each ladder's "true": the least-squares scale factor, nonlinearity and
/// asymmetry of the gyro's noise-free response over that ladder's rates at its temperature
/// (the model's nonlinearity is not a straight line, so the best line depends on the ladder).
nlohmann::json with_acceptance_truth(nlohmann::json serials, const sim::SimWorld& world,
                                     const Protocol& protocol);

}  // namespace station
