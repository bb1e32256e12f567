// Which fits belong to a run: every fit that used it, and the run's own (what its end-of-run
// summary, the API's run, the live page's results and its report show; later fits are dated
// notes in the report). One rule for all of them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// The fits of `serial` that used run `run_id`, oldest first.
std::vector<FitRecord> fits_of_run(Store& store, const std::string& serial, std::int64_t run_id);

/// Which of `fits` (fits_of_run's, oldest first) is the run's own: the first fitted on this run
/// alone (what `station run` stored when the run ended), else the first that used the run. A
/// later fit, whatever its model, never replaces it. Index into `fits`; empty when none.
std::optional<std::size_t> own_fit_index(const std::vector<FitRecord>& fits, std::int64_t run_id);

/// The run's own fit of `serial` (own_fit_index of fits_of_run); empty when none used the run.
std::optional<FitRecord> own_fit_of_run(Store& store, const std::string& serial,
                                        std::int64_t run_id);

}  // namespace station
