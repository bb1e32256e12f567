// A serial's acceptance verdict shown beside its thermal one (issue 36): in `fit` (the newest of
// the fit's runs that stored figures) and `verify` (the verification's run).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// The stored acceptance of `serial` from the newest of `runs` that has one: {run_id,
/// part_number, verdict, sf_pulse_per_arcsec}; null when none has.
nlohmann::json acceptance_beside_json(Store& store, const std::string& serial,
                                      const std::vector<std::int64_t>& runs);

/// Its line ("  acceptance verdict (run R, PN): ...\n"); empty for null.
std::string acceptance_beside_text(const nlohmann::json& a);

}  // namespace station
