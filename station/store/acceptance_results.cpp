// Acceptance figures stored per (run, serial): migration 12; their turn-on steps: migration 15.
#include "station/store/acceptance_results.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace station {
namespace {

using nlohmann::json;

/// A figure of a step's object: a number when the step was computed and has it.
std::optional<double> figure(const json& obj, const char* key) {
  if (!obj.is_object() || !obj.value("ok", false) || !obj.contains(key) || !obj[key].is_number())
    return std::nullopt;
  return obj[key].get<double>();
}

/// The step of `list` whose `key` is largest in magnitude, with its `se_key`.
std::pair<std::optional<double>, std::optional<double>> largest(const json& list, const char* key,
                                                                const char* se_key) {
  std::pair<std::optional<double>, std::optional<double>> out;
  if (!list.is_array()) return out;
  for (const auto& x : list) {
    const auto v = figure(x, key);
    if (v && (!out.first || std::abs(*v) > std::abs(*out.first)))
      out = {v, se_key == nullptr ? std::nullopt : figure(x, se_key)};
  }
  return out;
}

// The columns after run_id and serial, in the order rows are bound and read.
constexpr const char* kColumns =
    "computed_utc, part_number, pass, sf_pulse_per_arcsec, sf_se_pulse_per_arcsec, sf_temp_c, "
    "tc_ppm_per_c, tc_se_ppm_per_c, nonlinearity_max_ppm_fs, asymmetry_ppm, asymmetry_se_ppm, "
    "tilt_mrad, tilt_se_mrad, turn_on_repeatability_dph, turn_on_repeatability_lower_dph, "
    "turn_on_repeatability_upper_dph, max_warmup_s, figures_json";

/// The row's optional figures in kColumns' order (from sf_pulse_per_arcsec).
std::vector<std::optional<double>*> numbers(AcceptanceRow& r) {
  return {&r.sf_pulse_per_arcsec,
          &r.sf_se_pulse_per_arcsec,
          &r.sf_temp_c,
          &r.tc_ppm_per_c,
          &r.tc_se_ppm_per_c,
          &r.nonlinearity_max_ppm_fs,
          &r.asymmetry_ppm,
          &r.asymmetry_se_ppm,
          &r.tilt_mrad,
          &r.tilt_se_mrad,
          &r.turn_on_repeatability_dph,
          &r.turn_on_repeatability_lower_dph,
          &r.turn_on_repeatability_upper_dph,
          &r.max_warmup_s};
}

/// A value of `obj` of JSON type `T`, when it has one.
template <typename T>
std::optional<T> typed(const json& obj, const char* key) {
  if (!obj.contains(key)) return std::nullopt;
  const json& v = obj[key];
  if constexpr (std::is_same_v<T, std::string>) {
    if (v.is_string()) return v.get<std::string>();
  } else if constexpr (std::is_same_v<T, int>) {
    if (v.is_number_integer()) return v.get<int>();
  } else {
    if (v.is_number()) return v.get<double>();
  }
  return std::nullopt;
}

constexpr const char* kStepColumns =
    "step_no, step_index, label, temp_c, ok, error, turn_ons, repeatability_dph, "
    "repeatability_lower_dph, repeatability_upper_dph, max_warmup_s";

/// The step's optional figures in kStepColumns' order (from repeatability_dph).
std::vector<std::optional<double>*> step_numbers(TurnOnStepRow& t) {
  return {&t.repeatability_dph, &t.repeatability_lower_dph, &t.repeatability_upper_dph,
          &t.max_warmup_s};
}

void insert_steps(Store& store, std::int64_t run_id, const AcceptanceRow& r) {
  auto ins =
      store.db().prepare(std::string("INSERT INTO acceptance_turn_on_steps (run_id, serial, ") +
                         kStepColumns + ") VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?)");
  for (auto t : r.turn_on_steps) {
    ins.bind(1, run_id).bind(2, r.serial).bind(3, t.step_no);
    t.step_index ? ins.bind(4, *t.step_index) : ins.bind_null(4);
    t.label ? ins.bind(5, *t.label) : ins.bind_null(5);
    ins.bind(6, t.temp_c).bind(7, t.ok ? 1 : 0);
    t.error ? ins.bind(8, *t.error) : ins.bind_null(8);
    t.turn_ons ? ins.bind(9, *t.turn_ons) : ins.bind_null(9);
    int c = 10;
    for (auto* v : step_numbers(t)) ins.bind(c++, *v);
    ins.step();
    ins.reset();
  }
}

/// Each row's stored turn-on steps, in step order.
void read_steps(Store& store, std::vector<AcceptanceRow>& rows) {
  auto st = store.cached(std::string("SELECT ") + kStepColumns +
                         " FROM acceptance_turn_on_steps WHERE run_id = ? AND serial = ? ORDER "
                         "BY step_no");
  for (auto& r : rows) {
    st->bind(1, r.run_id).bind(2, r.serial);
    while (st->step()) {
      TurnOnStepRow t;
      t.step_no = static_cast<int>(st->column_int(0));
      if (!st->column_is_null(1)) t.step_index = static_cast<int>(st->column_int(1));
      if (!st->column_is_null(2)) t.label = st->column_text(2);
      if (!st->column_is_null(3)) t.temp_c = st->column_double(3);
      t.ok = st->column_int(4) != 0;
      if (!st->column_is_null(5)) t.error = st->column_text(5);
      if (!st->column_is_null(6)) t.turn_ons = static_cast<int>(st->column_int(6));
      int c = 7;
      for (auto* v : step_numbers(t)) {
        if (!st->column_is_null(c)) *v = st->column_double(c);
        ++c;
      }
      r.turn_on_steps.push_back(std::move(t));
    }
    st->reset();
  }
}

std::vector<AcceptanceRow> read_rows(StatementLease& st) {
  std::vector<AcceptanceRow> out;
  while (st->step()) {
    AcceptanceRow r;
    r.run_id = st->column_int(0);
    r.serial = st->column_text(1);
    r.computed_utc = st->column_text(2);
    if (!st->column_is_null(3)) r.part_number = st->column_text(3);
    if (!st->column_is_null(4)) r.pass = st->column_int(4) != 0;
    int c = 5;
    for (auto* v : numbers(r)) {
      if (!st->column_is_null(c)) *v = st->column_double(c);
      ++c;
    }
    r.figures = json::parse(st->column_text(c));
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace

std::vector<TurnOnStepRow> turn_on_step_rows(const json& serial) {
  std::vector<TurnOnStepRow> out;
  if (!serial.is_object()) return out;
  // Two or more steps: turn_on_steps (acceptance_json); one: its turn_on object.
  json one = json::array();
  const json* list = &one;
  if (serial.contains("turn_on_steps") && serial["turn_on_steps"].is_array())
    list = &serial["turn_on_steps"];
  else if (serial.contains("turn_on") && serial["turn_on"].is_object())
    one.push_back(serial["turn_on"]);
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& o = (*list)[i];
    if (!o.is_object()) continue;
    TurnOnStepRow t;
    t.step_no = static_cast<int>(i + 1);
    t.step_index = typed<int>(o, "step_index");
    t.label = typed<std::string>(o, "label");
    t.temp_c = typed<double>(o, "temp_c");
    t.ok = o.contains("ok") && o["ok"].is_boolean() && o["ok"].get<bool>();
    if (!t.ok) {
      t.error = typed<std::string>(o, "error").value_or("not computed");
    } else {
      t.turn_ons = typed<int>(o, "turn_ons");
      t.repeatability_dph = figure(o, "repeatability_dph");
      t.repeatability_lower_dph = figure(o, "repeatability_lower_dph");
      t.repeatability_upper_dph = figure(o, "repeatability_upper_dph");
      t.max_warmup_s = figure(o, "max_warmup_s");
    }
    out.push_back(std::move(t));
  }
  return out;
}

std::string turn_on_step_name(const TurnOnStepRow& s) {
  std::string out = s.label ? "'" + *s.label + "'" : "";
  std::string where = s.step_index ? fmt::format("step {}", *s.step_index + 1) : "";
  if (s.temp_c) where += fmt::format("{}{:.1f} C", where.empty() ? "" : ", ", *s.temp_c);
  if (where.empty()) return out;
  return out.empty() ? where : out + " (" + where + ")";
}

std::string turn_on_step_text(const TurnOnStepRow& t) {
  if (!t.ok) return "not computed: " + t.error.value_or("?");
  return fmt::format("sigma {} deg/h{}, longest warm-up {}",
                     t.repeatability_dph ? fmt::format("{:.3g}", *t.repeatability_dph) : "-",
                     t.repeatability_lower_dph && t.repeatability_upper_dph
                         ? fmt::format(" (interval {:.3g} to {:.3g})", *t.repeatability_lower_dph,
                                       *t.repeatability_upper_dph)
                         : "",
                     t.max_warmup_s ? fmt::format("{:.0f} s", *t.max_warmup_s) : "none settled");
}

json turn_on_steps_json(const std::vector<TurnOnStepRow>& steps) {
  const auto opt = [](const auto& v) { return v ? json(*v) : json(nullptr); };
  json out = json::array();
  for (const auto& t : steps)
    out.push_back({{"step_no", t.step_no},
                   {"step_index", opt(t.step_index)},
                   {"label", opt(t.label)},
                   {"temp_c", opt(t.temp_c)},
                   {"ok", t.ok},
                   {"error", opt(t.error)},
                   {"turn_ons", opt(t.turn_ons)},
                   {"repeatability_dph", opt(t.repeatability_dph)},
                   {"repeatability_lower_dph", opt(t.repeatability_lower_dph)},
                   {"repeatability_upper_dph", opt(t.repeatability_upper_dph)},
                   {"max_warmup_s", opt(t.max_warmup_s)}});
  return out;
}

std::optional<HeldScaleFactor> held_scale_factor(const json& serial) {
  if (serial.contains("sf_vs_temp")) {
    const json& t = serial["sf_vs_temp"];
    if (const auto k = figure(t, "sf_ref_pulse_per_arcsec"))
      return HeldScaleFactor{*k, figure(t, "sf_ref_se_pulse_per_arcsec").value_or(0.0),
                             figure(t, "ref_temp_c")};
  }
  // No temperature model (one ladder, or plateaus too close to give one): the computed ladder
  // nearest kHeldScaleFactorTempC holds at its own temperature.
  if (!serial.contains("ladders")) return std::nullopt;
  const json* best = nullptr;
  double best_gap = 0;
  for (const json& l : serial["ladders"]) {
    if (!figure(l, "sf_pulse_per_arcsec")) continue;
    const double gap = l.contains("temp_c") && l["temp_c"].is_number()
                           ? std::abs(l["temp_c"].get<double>() - kHeldScaleFactorTempC)
                           : 1e300;
    if (best == nullptr || gap < best_gap) best = &l, best_gap = gap;
  }
  if (best == nullptr) return std::nullopt;
  const json& l = *best;
  return HeldScaleFactor{
      *figure(l, "sf_pulse_per_arcsec"), figure(l, "sf_se_pulse_per_arcsec").value_or(0.0),
      l.contains("temp_c") && l["temp_c"].is_number() ? std::optional(l["temp_c"].get<double>())
                                                      : std::nullopt};
}

AcceptanceRow acceptance_row(std::int64_t run_id, const json& serial) {
  AcceptanceRow r;
  r.run_id = run_id;
  r.serial = serial.value("serial", "");
  r.figures = serial;
  if (serial.contains("verdict")) {
    r.part_number = serial["verdict"].value("part", "");
    r.pass = serial["verdict"].value("pass", false);
  }
  if (const auto k = held_scale_factor(serial)) {
    r.sf_pulse_per_arcsec = k->k_pulse_per_arcsec;
    r.sf_se_pulse_per_arcsec = k->se_pulse_per_arcsec;
    r.sf_temp_c = k->temp_c;
  }
  const json none;
  const json& t = serial.contains("sf_vs_temp") ? serial["sf_vs_temp"] : none;
  r.tc_ppm_per_c = figure(t, "tc_ppm_per_c");
  r.tc_se_ppm_per_c = figure(t, "tc_se_ppm_per_c");
  const json& ladders = serial.contains("ladders") ? serial["ladders"] : none;
  r.nonlinearity_max_ppm_fs = largest(ladders, "nonlinearity_max_ppm_fs", nullptr).first;
  std::tie(r.asymmetry_ppm, r.asymmetry_se_ppm) =
      largest(ladders, "asymmetry_ppm", "asymmetry_se_ppm");
  std::tie(r.tilt_mrad, r.tilt_se_mrad) = largest(
      serial.contains("positions") ? serial["positions"] : none, "tilt_mrad", "tilt_se_mrad");
  const json& on = serial.contains("turn_on") ? serial["turn_on"] : none;
  r.turn_on_repeatability_dph = figure(on, "repeatability_dph");
  r.turn_on_repeatability_lower_dph = figure(on, "repeatability_lower_dph");
  r.turn_on_repeatability_upper_dph = figure(on, "repeatability_upper_dph");
  r.max_warmup_s = figure(on, "max_warmup_s");
  r.turn_on_steps = turn_on_step_rows(serial);
  return r;
}

void replace_acceptance_rows(Store& store, std::int64_t run_id,
                             const std::vector<AcceptanceRow>& rows) {
  store.flush();
  Transaction tx(store.db());
  for (const char* table : {"acceptance_turn_on_steps", "acceptance_results"}) {
    auto del = store.db().prepare(fmt::format("DELETE FROM {} WHERE run_id = ?", table));
    del.bind(1, run_id);
    del.step();
  }
  auto ins = store.db().prepare(std::string("INSERT INTO acceptance_results (run_id, serial, ") +
                                kColumns + ") VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)");
  const std::string now = utc_now_iso();
  for (auto r : rows) {
    ins.bind(1, run_id).bind(2, r.serial).bind(3, now);
    r.part_number ? ins.bind(4, *r.part_number) : ins.bind_null(4);
    r.pass ? ins.bind(5, *r.pass ? 1 : 0) : ins.bind_null(5);
    int c = 6;
    for (auto* v : numbers(r)) ins.bind(c++, *v);
    ins.bind(c, r.figures.dump());
    ins.step();
    ins.reset();
    insert_steps(store, run_id, r);
  }
  tx.commit();
}

std::vector<AcceptanceRow> acceptance_rows_of_run(Store& store, std::int64_t run_id) {
  auto st = store.cached(std::string("SELECT run_id, serial, ") + kColumns +
                         " FROM acceptance_results WHERE run_id = ? ORDER BY rowid");
  st->bind(1, run_id);
  auto rows = read_rows(st);
  read_steps(store, rows);
  return rows;
}

std::vector<AcceptanceRow> acceptance_rows_of_serial(Store& store, const std::string& serial) {
  auto st = store.cached(std::string("SELECT run_id, serial, ") + kColumns +
                         " FROM acceptance_results WHERE serial = ? ORDER BY run_id");
  st->bind(1, serial);
  auto rows = read_rows(st);
  read_steps(store, rows);
  return rows;
}

std::optional<AcceptanceRow> newest_acceptance_row(Store& store, const std::string& serial,
                                                   const std::vector<std::int64_t>& runs) {
  std::optional<AcceptanceRow> out;
  for (auto& r : acceptance_rows_of_serial(store, serial))  // oldest run first
    if (std::find(runs.begin(), runs.end(), r.run_id) != runs.end()) out = std::move(r);
  return out;
}

json stored_acceptance_json(Store& store, std::int64_t run_id) {
  json out = json::array();
  for (auto& r : acceptance_rows_of_run(store, run_id)) out.push_back(std::move(r.figures));
  return out;
}

}  // namespace station
