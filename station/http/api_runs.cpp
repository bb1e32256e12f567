// Run queries for the API: plain SQL on a read-only connection (WAL: never blocks the writer).
#include "station/http/api_runs.hpp"

#include "station/parts/judged_fit.hpp"
#include "station/parts/run_results.hpp"
#include "station/release/releases.hpp"
#include "station/release/verification.hpp"
#include "station/report/report_page.hpp"
#include "station/store/acceptance_results.hpp"
#include "station/store/fit_json.hpp"
#include "station/store/run_fits.hpp"

namespace station::http {

namespace {

nlohmann::json text_or_null(const Statement& st, int c) {
  return st.column_is_null(c) ? nlohmann::json(nullptr) : nlohmann::json(st.column_text(c));
}

nlohmann::json real_or_null(const Statement& st, int c) {
  return st.column_is_null(c) ? nlohmann::json(nullptr) : nlohmann::json(st.column_double(c));
}

constexpr const char* kRunColumns =
    "SELECT id, state, protocol_name, operator, started_utc, ended_utc, t_s, sim_seed, station, "
    "software_version, step_index FROM runs";

nlohmann::json run_row(const Statement& st) {
  return {{"id", st.column_int(0)},
          {"state", st.column_text(1)},
          {"protocol", st.column_text(2)},
          {"operator", st.column_text(3)},
          {"started_utc", st.column_text(4)},
          {"ended_utc", text_or_null(st, 5)},
          {"last_tick_s", st.column_double(6)},
          {"sim_seed",
           st.column_is_null(7) ? nlohmann::json(nullptr) : nlohmann::json(st.column_int(7))},
          {"station", st.column_text(8)},
          {"software_version", st.column_text(9)},
          {"step_index", st.column_int(10)}};
}

bool run_exists(Store& store, std::int64_t run_id) {
  auto st = store.db().prepare("SELECT 1 FROM runs WHERE id = ?");
  st.bind(1, run_id);
  return st.step();
}

}  // namespace

nlohmann::json runs_json(Store& store, int limit) {
  auto st = store.db().prepare(std::string(kRunColumns) + " ORDER BY id DESC LIMIT ?");
  st.bind(1, limit);
  nlohmann::json out = nlohmann::json::array();
  while (st.step()) out.push_back(run_row(st));
  return out;
}

std::optional<nlohmann::json> run_json(Store& store, std::int64_t run_id) {
  auto st = store.db().prepare(std::string(kRunColumns) + " WHERE id = ?");
  st.bind(1, run_id);
  if (!st.step()) return std::nullopt;
  nlohmann::json j = run_row(st);
  nlohmann::json slots = nlohmann::json::array();
  bool any_fit = false;
  for (const auto& s : store.run_slots(run_id)) {
    nlohmann::json slot{{"slot", s.slot},
                        {"node", s.node},
                        {"serial", s.serial},
                        {"axis", s.axis},
                        {"earth_rate_dph", s.earth_rate_dph},
                        {"fit", nullptr}};
    if (const auto f = own_fit_of_run(store, s.serial, run_id)) {  // store/run_fits.hpp
      slot["fit"] = {{"id", f->id},
                     {"terms", f->terms},
                     {"coefficients", coefficients_json(f->fit)},
                     {"units", units_json(f->fit)},
                     {"std_errors", std_errors_json(f->fit)},
                     {"std_before_dph", f->eval.std_before_dph},
                     {"std_after_dph", f->eval.std_after_dph},
                     {"std_ratio", std_ratio_json(f->eval)}};
      const auto verdict = stored_verdict(store, f->id);  // null: judged against no part
      slot["fit"]["part_number"] = verdict ? nlohmann::json(verdict->part_number) : nullptr;
      slot["fit"]["verdict"] = verdict ? verdict_json(*verdict) : nullptr;
      slot["fit"]["verdict_text"] = slot_verdict_text(verdict, s.slot);
      any_fit = true;
    }
    // The serial's released calibration (it may come from another run) and its release.
    slot["released"] = nullptr;
    if (const auto r = current_release(store, s.serial)) slot["released"] = release_json(*r);
    slots.push_back(std::move(slot));
  }
  j["slots"] = std::move(slots);
  // Its report, served from the store (GET /reports/NAME): a run without a fit has none.
  j["report"] = any_fit ? nlohmann::json("/reports/" + report::index_page_name(run_id)) : nullptr;
  nlohmann::json verifications = nlohmann::json::array();
  for (const auto& v : verifications_of_run(store, run_id))
    verifications.push_back(verification_json(v));
  j["verifications"] = std::move(verifications);
  return j;
}

std::optional<nlohmann::json> bins_json(Store& store, std::int64_t run_id,
                                        const std::optional<nlohmann::json>& live) {
  if (!run_exists(store, run_id)) return std::nullopt;
  auto st = store.db().prepare(
      "SELECT serial, t_start_s, n, bias_dph, temp_c, grad_c, complete FROM bins "
      "WHERE run_id = ? ORDER BY serial, t_start_s");
  st.bind(1, run_id);
  nlohmann::json serials = nlohmann::json::object();
  bool any = false;
  while (st.step()) {
    any = true;
    serials[st.column_text(0)].push_back({{"t_start_s", st.column_double(1)},
                                          {"n", st.column_int(2)},
                                          {"bias_dph", real_or_null(st, 3)},
                                          {"temp_c", real_or_null(st, 4)},
                                          {"grad_c", real_or_null(st, 5)},
                                          {"complete", st.column_int(6) != 0}});
  }
  if (!any && live) return nlohmann::json{{"provisional", true}, {"serials", *live}};
  return nlohmann::json{{"provisional", false}, {"serials", serials}};
}

std::optional<nlohmann::json> events_json(Store& store, std::int64_t run_id,
                                          std::int64_t since_id) {
  if (!run_exists(store, run_id)) return std::nullopt;
  auto st = store.db().prepare(
      "SELECT id, t_s, severity, source, kind, message FROM events WHERE run_id = ? AND id > ? "
      "ORDER BY id LIMIT 1000");
  st.bind(1, run_id).bind(2, since_id);
  nlohmann::json events = nlohmann::json::array();
  std::int64_t next = since_id;
  while (st.step()) {
    next = st.column_int(0);
    events.push_back({{"id", next},
                      {"run_id", run_id},
                      {"t_s", st.column_double(1)},
                      {"severity", st.column_text(2)},
                      {"source", st.column_text(3)},
                      {"kind", st.column_text(4)},
                      {"message", st.column_text(5)}});
  }
  return nlohmann::json{{"events", events}, {"next", next}};
}

std::optional<nlohmann::json> acceptance_results_json(Store& store, std::int64_t run_id) {
  if (!run_exists(store, run_id)) return std::nullopt;
  nlohmann::json serials = nlohmann::json::array(), computed = nullptr;
  for (auto& r : acceptance_rows_of_run(store, run_id)) {
    computed = r.computed_utc;
    serials.push_back(std::move(r.figures));
  }
  return nlohmann::json{{"run_id", run_id}, {"computed_utc", computed}, {"serials", serials}};
}

}  // namespace station::http
