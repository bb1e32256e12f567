// Which model terms a released calibration can carry: gyro_tc_correct() (station/release/
// gyro_tc.h, the C function the navigation computer runs) applies B0, k1..k4 (dT..dT4) and k0
// (gradT) only. A part's production model (its part file's `model`), `fit --select`'s choices
// and a release all ask this one list.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "compensation/fit.hpp"

namespace station {

/// Whether gyro_tc_correct() applies term `t`.
bool deliverable_term(compensation::Term t);

/// The terms of `terms` that cannot be delivered, as one sentence; empty when all can.
std::optional<std::string> undeliverable_terms(std::span<const compensation::Term> terms);

/// `terms` without the ones that cannot be delivered.
std::vector<compensation::Term> deliverable_only(std::span<const compensation::Term> terms);

}  // namespace station
