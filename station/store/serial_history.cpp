// Per-serial reads over runs and fits (run_slots, fits; migration 5 for the part columns).
#include "station/store/serial_history.hpp"

#include <nlohmann/json.hpp>

namespace station {
namespace {

using nlohmann::json;

std::optional<double> lookup(const std::vector<std::pair<std::string, double>>& v,
                             const std::string& name) {
  for (const auto& [n, x] : v)
    if (n == name) return x;
  return std::nullopt;
}

std::optional<std::string> opt_text(const StatementLease& st, int c) {
  return st->column_is_null(c) ? std::nullopt : std::optional(st->column_text(c));
}

}  // namespace

std::vector<std::pair<std::string, double>> values_by_name(const std::string& json_text) {
  std::vector<std::pair<std::string, double>> out;
  const json j = json::parse(json_text);  // items() of a temporary would dangle
  for (const auto& [k, v] : j.items())
    if (v.is_number()) out.emplace_back(k, v.get<double>());
  return out;
}

std::optional<double> SerialFitRow::coefficient(const std::string& name) const {
  return lookup(coefficients, name);
}

std::optional<double> SerialFitRow::std_error(const std::string& name) const {
  return lookup(std_errors, name);
}

std::vector<std::string> all_serials(Store& store) {
  auto st = store.cached("SELECT DISTINCT serial FROM run_slots ORDER BY serial");
  std::vector<std::string> out;
  while (st->step()) out.push_back(st->column_text(0));
  return out;
}

std::vector<SerialRun> serial_runs(Store& store, const std::string& serial) {
  auto st = store.cached(
      "SELECT r.id, r.started_utc, r.ended_utc, r.state, r.protocol_name, r.station, r.operator, "
      "s.slot, s.part_number FROM runs AS r JOIN run_slots AS s ON s.run_id = r.id "
      "WHERE s.serial = ? ORDER BY r.id");
  st->bind(1, serial);
  std::vector<SerialRun> out;
  while (st->step()) {
    SerialRun r;
    r.run_id = st->column_int(0);
    r.started_utc = st->column_text(1);
    r.ended_utc = st->column_text(2);
    r.state = st->column_text(3);
    r.protocol_name = st->column_text(4);
    r.station = st->column_text(5);
    r.operator_name = st->column_text(6);
    r.slot = static_cast<int>(st->column_int(7));
    r.part_number = opt_text(st, 8);
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<SerialFitRow> serial_fits(Store& store, const std::string& serial) {
  auto st = store.cached(
      "SELECT id, created_utc, terms, runs_json, coefficients_json, std_errors_json, n_bins, "
      "std_ratio, std_after_dph, part_number, verdict_json FROM fits WHERE serial = ? "
      "ORDER BY id");
  st->bind(1, serial);
  std::vector<SerialFitRow> out;
  while (st->step()) {
    SerialFitRow f;
    f.fit_id = st->column_int(0);
    f.created_utc = st->column_text(1);
    f.terms = st->column_text(2);
    f.runs = json::parse(st->column_text(3)).get<std::vector<std::int64_t>>();
    f.coefficients = values_by_name(st->column_text(4));
    f.std_errors = values_by_name(st->column_text(5));
    f.n_bins = st->column_int(6);
    if (!st->column_is_null(7)) f.std_ratio = st->column_double(7);
    f.std_after_dph = st->column_double(8);
    f.part_number = opt_text(st, 9);
    f.verdict_json = opt_text(st, 10);
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace station
