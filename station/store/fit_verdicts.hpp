// The verdict columns of fits and the part columns of run_slots (migration 5), kept apart from
// Store's own fit rows: a verdict is written after its fit, by the parts room, as JSON text.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// A fit's verdict as stored; all empty for a fit judged against no part.
struct StoredVerdict {
  std::optional<std::string> part_number;
  std::optional<std::string> verdict_json;  ///< station/parts/verdict.hpp, verdict_json
  std::optional<double> adev_floor_dph;     ///< ADEV floor of the compensated 1 Hz record
};

/// Writes the verdict columns of fit `fit_id`.
void save_fit_verdict(Store& store, std::int64_t fit_id, const StoredVerdict& v);
/// Reads them back (all empty for a fit stored without, or before migration 5).
StoredVerdict load_fit_verdict(Store& store, std::int64_t fit_id);

/// The part a run's slot named and the snapshot of its limits.
struct SlotPart {
  std::string serial, part_number, limits_json;
};
/// Stores the part of each listed serial's slot in `run_id`.
void save_run_parts(Store& store, std::int64_t run_id, const std::vector<SlotPart>& parts);
/// The part `serial` had in the newest of `runs` that gave it one; empty when none did.
std::optional<SlotPart> find_run_part(Store& store, const std::string& serial,
                                      const std::vector<std::int64_t>& runs);

}  // namespace station
