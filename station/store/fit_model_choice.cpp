// How a fit's model was chosen (see the header).
#include "station/store/fit_model_choice.hpp"

#include <fmt/format.h>

namespace station {
namespace {

nlohmann::json or_null(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json();
}

}  // namespace

nlohmann::json model_selection_json(const compensation::ModelSelection& sel) {
  nlohmann::json tried = nlohmann::json::array();
  for (const auto& m : sel.tried)
    tried.push_back({{"model", compensation::model_text(m.spec)},
                     {"step", m.step},
                     {"added", m.added},
                     {"held_out_rms_dph", or_null(m.held_out_rms_dph)},
                     {"likelihood_ratio", or_null(m.likelihood_ratio)},
                     {"not_fitted", m.not_fitted ? nlohmann::json(*m.not_fitted) : nullptr},
                     {"chosen", m.chosen}});
  return {{"method", sel.method},
          {"chosen", compensation::model_text(sel.chosen)},
          {"reason", sel.reason},
          {"tried", tried}};
}

nlohmann::json part_model_choice_json(const std::string& part_number, const std::string& model) {
  compensation::ModelSpec spec;
  spec.terms = compensation::parse_terms(model);
  return {{"method", "part file"},
          {"part_number", part_number},
          {"chosen", compensation::model_text(spec)},
          {"reason", fmt::format("part {} fixes the model for production", part_number)}};
}

std::string model_selection_text(const compensation::ModelSelection& sel) {
  std::string out = fmt::format("  model selection ({}):\n", sel.method);
  for (const auto& m : sel.tried) {
    std::string figure =
        m.not_fitted         ? "not fitted: " + *m.not_fitted
        : m.held_out_rms_dph ? fmt::format("held-out RMS {:.5f} deg/h", *m.held_out_rms_dph)
        : m.likelihood_ratio ? fmt::format("likelihood ratio {:.1f}", *m.likelihood_ratio)
                             : std::string("the base");
    out += fmt::format("  {} step {} {:<24} {}\n", m.chosen ? "*" : " ", m.step,
                       compensation::model_text(m.spec), figure);
  }
  return out + fmt::format("  chosen {}\n", sel.reason);
}

void save_fit_model_choice(Store& store, std::int64_t fit_id, const nlohmann::json& choice) {
  auto st = store.cached("UPDATE fits SET model_choice_json = ? WHERE id = ?");
  st->bind(1, choice.dump()).bind(2, fit_id);
  st->step();
}

std::optional<nlohmann::json> load_fit_model_choice(Store& store, std::int64_t fit_id) {
  auto st = store.cached("SELECT model_choice_json FROM fits WHERE id = ?");
  st->bind(1, fit_id);
  if (!st->step() || st->column_is_null(0)) return std::nullopt;
  return nlohmann::json::parse(st->column_text(0));
}

}  // namespace station
