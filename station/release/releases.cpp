// Releasing fits: the refusal rules, the stored row and its event in one transaction.
#include "station/release/releases.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "station/common/text_rule.hpp"
#include "station/parts/verdict.hpp"
#include "station/release/coefficient_block.hpp"
#include "station/store/fit_verdicts.hpp"

namespace station {
namespace {

constexpr const char* kReleaseColumns =
    "SELECT id, fit_id, serial, released_utc, released_by, note, override_reason, verdict_json "
    "FROM releases ";

ReleaseRow read_release(const Statement& st) {
  ReleaseRow r;
  r.id = st.column_int(0);
  r.fit_id = st.column_int(1);
  r.serial = st.column_text(2);
  r.released_utc = st.column_text(3);
  r.released_by = st.column_text(4);
  r.note = st.column_text(5);
  if (!st.column_is_null(6)) r.override_reason = st.column_text(6);
  if (!st.column_is_null(7)) r.verdict_json = st.column_text(7);
  return r;
}

/// Why the fit may not be released without an override; empty when it may.
std::optional<std::string> needs_override(Store& store, const FitRecord& fit,
                                          const StoredVerdict& v) {
  if (v.verdict_json) {
    const Verdict verdict = verdict_from_json(nlohmann::json::parse(*v.verdict_json));
    if (!verdict.pass) return fmt::format("its verdict failed: {}", verdict_text(verdict));
    return std::nullopt;
  }
  if (const auto part = find_run_part(store, fit.serial, fit.runs))
    return fmt::format("it has no verdict although its run names part {} (run `station fit`)",
                       part->part_number);
  return std::nullopt;
}

/// Free text of a release, by the text rule (common/text_rule.hpp): it reaches a one-line audit
/// trail and every export; `required` refuses a blank one. `what` names the CLI option and the
/// API's JSON field.
void check_text(const char* what, const std::string& text, std::size_t max_bytes, bool required) {
  if (required && text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(fmt::format("release: {}: must not be empty", what));
  require_note(fmt::format("release: {}", what), text, max_bytes);
}

void check_request(Store& store, const ReleaseRequest& req, const FitRecord& fit,
                   const StoredVerdict& v) {
  check_text("--by NAME (who releases; JSON 'by')", req.by, kMaxPersonBytes, true);
  check_text("--note (JSON 'note')", req.note, kMaxNoteBytes, false);
  if (req.override_reason)
    check_text("--override REASON (JSON 'override')", *req.override_reason, kMaxNoteBytes, true);
  if (const auto bad = undeliverable_term(fit.fit))
    throw ReleaseRefused(fmt::format("fit {} of {}: {}", fit.id, fit.serial, *bad));
  if (const auto cur = current_release(store, fit.serial); cur && cur->fit_id == fit.id)
    throw ReleaseRefused(fmt::format("fit {} is already the released calibration of {} ({})",
                                     fit.id, fit.serial, release_text(*cur)));
  const auto why = needs_override(store, fit, v);
  if (why && !req.override_reason)
    throw ReleaseRefused(
        fmt::format("fit {} of {} is not released: {}; give --override REASON "
                    "to release it anyway",
                    fit.id, fit.serial, *why));
  // An override is a statement that a rule was set aside: on a fit no rule holds back, it would
  // put a false "released over its verdict" into the record.
  if (!why && req.override_reason)
    throw ReleaseRefused(
        fmt::format("fit {} of {} needs no override ({}): release it without "
                    "--override",
                    fit.id, fit.serial, v.verdict_json ? "its verdict passed" : "no part applies"));
}

void add_release_event(Store& store, const FitRecord& fit, const ReleaseRow& r) {
  const std::int64_t run = *std::max_element(fit.runs.begin(), fit.runs.end());
  const auto rec = store.find_run(run);
  const double t_s = rec && rec->last_tick_s ? *rec->last_tick_s : 0.0;
  const nlohmann::json data{
      {"fit_id", r.fit_id},
      {"serial", r.serial},
      {"by", r.released_by},
      {"override", r.override_reason ? nlohmann::json(*r.override_reason) : nlohmann::json()}};
  store.add_event(run, t_s, r.override_reason ? Severity::warn : Severity::info, "release",
                  EventKind::release,
                  fmt::format("{}: fit {} {}", r.serial, r.fit_id, release_text(r)), data);
}

}  // namespace

ReleaseRow release_fit(Store& store, const ReleaseRequest& req) {
  Transaction tx(store.db());
  const auto fit = store.find_fit(req.fit_id);
  if (!fit) throw FitNotFound(fmt::format("{}: no fit {}", store.db().path(), req.fit_id));
  const StoredVerdict v = load_fit_verdict(store, fit->id);
  check_request(store, req, *fit, v);
  ReleaseRow r{0,      fit->id,  fit->serial,         utc_now_iso(),
               req.by, req.note, req.override_reason, v.verdict_json};
  auto st = store.db().prepare(
      "INSERT INTO releases (fit_id, serial, released_utc, released_by, note, override_reason, "
      "verdict_json) VALUES (?,?,?,?,?,?,?)");
  st.bind(1, r.fit_id).bind(2, r.serial).bind(3, r.released_utc).bind(4, r.released_by);
  st.bind(5, r.note);
  r.override_reason ? st.bind(6, *r.override_reason) : st.bind_null(6);
  r.verdict_json ? st.bind(7, *r.verdict_json) : st.bind_null(7);
  st.step();
  r.id = store.db().last_insert_id();
  add_release_event(store, *fit, r);
  tx.commit();
  return r;
}

std::optional<ReleaseRow> current_release(Store& store, const std::string& serial) {
  auto st =
      store.cached(std::string(kReleaseColumns) + "WHERE serial = ? ORDER BY id DESC LIMIT 1");
  st->bind(1, serial);
  if (!st->step()) return std::nullopt;
  return read_release(*st);
}

std::vector<ReleaseRow> releases_of(Store& store, const std::string& serial) {
  auto st = store.cached(std::string(kReleaseColumns) + "WHERE serial = ? ORDER BY id");
  st->bind(1, serial);
  std::vector<ReleaseRow> out;
  while (st->step()) out.push_back(read_release(*st));
  return out;
}

std::optional<ReleaseRow> release_of_fit(Store& store, std::int64_t fit_id) {
  auto st =
      store.cached(std::string(kReleaseColumns) + "WHERE fit_id = ? ORDER BY id DESC LIMIT 1");
  st->bind(1, fit_id);
  if (!st->step()) return std::nullopt;
  return read_release(*st);
}

nlohmann::json release_json(const ReleaseRow& r) {
  return {{"release_id", r.id},
          {"fit_id", r.fit_id},
          {"serial", r.serial},
          {"released_utc", r.released_utc},
          {"by", r.released_by},
          {"note", r.note},
          {"override", r.override_reason ? nlohmann::json(*r.override_reason) : nullptr}};
}

std::string release_text(const ReleaseRow& r) {
  std::string s = fmt::format("released {} by {}", r.released_utc, r.released_by);
  if (!r.note.empty()) s += fmt::format(" ({})", r.note);
  if (r.override_reason) s += fmt::format(" [override: {}]", *r.override_reason);
  return s;
}

}  // namespace station
