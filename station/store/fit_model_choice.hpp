// How a fit's model was chosen (migration 9): `station fit --select`'s table of the models it
// tried and why it kept one, stored with the fit as JSON text. A release refers to its fit, so
// it carries the choice too.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "compensation/model_selection.hpp"
#include "station/store/store.hpp"

namespace station {

/// {"method", "chosen", "reason", "tried": [{"model", "step", "added", "held_out_rms_dph",
/// "likelihood_ratio", "not_fitted", "chosen"}]} (absent numbers are null).
nlohmann::json model_selection_json(const compensation::ModelSelection& sel);

/// {"method": "part file", "part_number", "chosen", "reason"}: the part fixes the model.
nlohmann::json part_model_choice_json(const std::string& part_number, const std::string& model);

/// The table people read: one line per model tried, the chosen one marked, then the reason.
std::string model_selection_text(const compensation::ModelSelection& sel);

/// Writes fit `fit_id`'s model_choice_json.
void save_fit_model_choice(Store& store, std::int64_t fit_id, const nlohmann::json& choice);
/// Reads it back (empty: the terms were given, or the fit is older than migration 9).
std::optional<nlohmann::json> load_fit_model_choice(Store& store, std::int64_t fit_id);

}  // namespace station
