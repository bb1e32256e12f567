// The API's read side over the database (schemas/api.md): runs, one run, its bins, its events,
// its acceptance figures.
// Each function takes a read-only Store and returns the JSON body, or nullopt for an unknown run.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>

#include "station/store/store.hpp"

namespace station::http {

nlohmann::json runs_json(Store& store, int limit);
std::optional<nlohmann::json> run_json(Store& store, std::int64_t run_id);
/// Stored bins per serial; `live` (the daemon's live bins of a running run) when none is stored.
std::optional<nlohmann::json> bins_json(Store& store, std::int64_t run_id,
                                        const std::optional<nlohmann::json>& live);
std::optional<nlohmann::json> events_json(Store& store, std::int64_t run_id, std::int64_t since_id);
/// The run's acceptance figures as stored when it ended (migration 12): {"run_id",
/// "computed_utc" (null: none stored), "serials": [acceptance_json's objects with "verdict"]}.
std::optional<nlohmann::json> acceptance_results_json(Store& store, std::int64_t run_id);

}  // namespace station::http
