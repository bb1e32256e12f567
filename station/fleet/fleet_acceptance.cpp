// The acceptance figures across the fleet: read, charted, said.
#include "station/fleet/fleet_acceptance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "compensation/control_chart.hpp"
#include "station/fleet/fleet_schema.hpp"
#include "station/store/acceptance_results.hpp"

namespace station::fleet {
namespace {

using nlohmann::json;
namespace sc = station::compensation;

json opt(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

std::optional<double> opt_number(const PgResult& r, int i, int c) {
  return r.is_null(i, c) ? std::nullopt : std::optional(r.number(i, c));
}

bool held_near_reference(const AcceptancePoint& p) {
  return p.sf_temp_c && std::abs(*p.sf_temp_c - kHeldScaleFactorTempC) <= kHeldTempToleranceC;
}

/// A figure of one result: K or TC with its standard error.
struct Metric {
  const char* name;
  const char* unit;
  std::optional<double> AcceptancePoint::*value;
  std::optional<double> AcceptancePoint::*se;
};
const Metric kMetrics[] = {
    {"K", "pulse/arcsec", &AcceptancePoint::sf_pulse_per_arcsec,
     &AcceptancePoint::sf_se_pulse_per_arcsec},
    {"TC", "ppm/C", &AcceptancePoint::tc_ppm_per_c, &AcceptancePoint::tc_se_ppm_per_c}};

json chart_json(const std::optional<sc::IndividualsChart>& c) {
  if (!c) return nullptr;
  return {{"n", c->n},         {"centre", c->centre}, {"mr_bar", c->mr_bar},
          {"sigma", c->sigma}, {"lcl", c->lcl},       {"ucl", c->ucl}};
}

// The chart's limits pool the moving ranges within each station (individuals_chart with groups,
// as the thermal charts do); K held at another temperature is drawn but not in the limits.
json metric_json(const Metric& m, const std::vector<const AcceptancePoint*>& pts, json& outside) {
  std::vector<double> values;
  std::vector<int> group;
  std::vector<std::size_t> charted;
  std::map<std::string, int> station_index;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto* p = pts[i];
    if (!(p->*m.value) ||
        (m.value == &AcceptancePoint::sf_pulse_per_arcsec && !held_near_reference(*p)))
      continue;
    values.push_back(*(p->*m.value));
    group.push_back(station_index.try_emplace(p->station, static_cast<int>(station_index.size()))
                        .first->second);
    charted.push_back(i);
  }
  const auto chart = sc::individuals_chart(values, group);
  json jp = json::array();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto* p = pts[i];
    if (!(p->*m.value)) continue;
    const double v = *(p->*m.value);
    const bool in_chart = std::find(charted.begin(), charted.end(), i) != charted.end();
    const bool out = in_chart && chart && chart->sigma > 0 && (v < chart->lcl || v > chart->ucl);
    json q{{"x", i + 1},
           {"station", p->station},
           {"serial", p->serial},
           {"run_fleet_id", p->run_fleet_id},
           {"run_started_utc", p->run_started_utc},
           {"value", v},
           {"se", opt(p->*m.se)},
           {"in_limits_chart", in_chart},
           {"outside_overall", out}};
    if (m.value == &AcceptancePoint::sf_pulse_per_arcsec) q["held_temp_c"] = opt(p->sf_temp_c);
    if (out)
      outside.push_back({{"metric", m.name},
                         {"unit", m.unit},
                         {"station", p->station},
                         {"serial", p->serial},
                         {"run_fleet_id", p->run_fleet_id},
                         {"run_started_utc", p->run_started_utc},
                         {"value", v},
                         {"limit", v > chart->ucl ? "UCL" : "LCL"}});
    jp.push_back(std::move(q));
  }
  return {{"metric", m.name}, {"unit", m.unit}, {"overall", chart_json(chart)}, {"points", jp}};
}

json result_json(const AcceptancePoint& p, std::size_t x) {
  const auto why = [](const std::string& s) { return s.empty() ? json(nullptr) : json(s); };
  return {{"x", x},
          {"station", p.station},
          {"serial", p.serial},
          {"run_fleet_id", p.run_fleet_id},
          {"run_started_utc", p.run_started_utc},
          {"computed_utc", p.computed_utc},
          {"pass", p.pass ? json(*p.pass) : json(nullptr)},
          {"sf_pulse_per_arcsec", opt(p.sf_pulse_per_arcsec)},
          {"sf_se_pulse_per_arcsec", opt(p.sf_se_pulse_per_arcsec)},
          {"sf_temp_c", opt(p.sf_temp_c)},
          {"sf_missing", why(p.sf_missing)},
          {"tc_ppm_per_c", opt(p.tc_ppm_per_c)},
          {"tc_se_ppm_per_c", opt(p.tc_se_ppm_per_c)},
          {"tc_missing", why(p.tc_missing)},
          {"turn_on_steps", turn_on_steps_json(p.turn_on_steps)}};
}

bool has_table(PgConnection& pg, const char* name) {
  return pg.exec("SELECT to_regclass($1) IS NOT NULL", {std::string(name)}).text(0, 0) == "t";
}

/// Each point's power_cycles steps from the central acceptance_turn_on_steps (schema 7).
void read_turn_on_steps(PgConnection& pg, std::vector<AcceptancePoint>& points) {
  if (points.empty() || !has_table(pg, "acceptance_turn_on_steps")) return;
  std::map<std::pair<std::int64_t, std::string>, AcceptancePoint*> by_key;
  for (auto& p : points) by_key[{p.run_fleet_id, p.serial}] = &p;
  auto r = pg.exec(
      "SELECT r.fleet_id, t.serial, t.step_no, t.step_index, t.label, t.temp_c, t.ok, t.error, "
      "t.turn_ons, t.repeatability_dph, t.repeatability_lower_dph, t.repeatability_upper_dph, "
      "t.max_warmup_s FROM acceptance_turn_on_steps AS t JOIN runs AS r ON r.uuid = t.run_uuid "
      "ORDER BY r.fleet_id, t.serial, t.step_no");
  for (int i = 0; i < r.rows(); ++i) {
    const auto it = by_key.find({r.integer(i, 0), r.text(i, 1)});
    if (it == by_key.end()) continue;  // a result the filter left out
    TurnOnStepRow t;
    t.step_no = static_cast<int>(r.integer(i, 2));
    if (!r.is_null(i, 3)) t.step_index = static_cast<int>(r.integer(i, 3));
    t.label = r.opt_text(i, 4);
    t.temp_c = opt_number(r, i, 5);
    t.ok = r.integer(i, 6) != 0;
    t.error = r.opt_text(i, 7);
    if (!r.is_null(i, 8)) t.turn_ons = static_cast<int>(r.integer(i, 8));
    t.repeatability_dph = opt_number(r, i, 9);
    t.repeatability_lower_dph = opt_number(r, i, 10);
    t.repeatability_upper_dph = opt_number(r, i, 11);
    t.max_warmup_s = opt_number(r, i, 12);
    it->second->turn_on_steps.push_back(std::move(t));
  }
}

json part_json(const std::string& part, const std::vector<const AcceptancePoint*>& pts) {
  json charts = json::array(), outside = json::array(), results = json::array();
  json verdicts = json::object();
  std::map<std::string, int> stations;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto* p = pts[i];
    ++stations[p->station];
    auto& v = verdicts[p->station];
    if (v.is_null()) v = {{"pass", 0}, {"fail", 0}, {"none", 0}};
    const char* k = !p->pass ? "none" : *p->pass ? "pass" : "fail";
    v[k] = v[k].get<int>() + 1;
    results.push_back(result_json(*p, i + 1));
  }
  for (const auto& m : kMetrics) charts.push_back(metric_json(m, pts, outside));
  return {{"part", part},
          {"results", pts.size()},
          {"stations", stations},
          {"verdicts", verdicts},
          {"held_temp_c", kHeldScaleFactorTempC},
          {"charts", charts},
          {"results_list", results},
          {"outside", outside}};
}

}  // namespace

std::string scale_factor_missing(const json& serial) {
  if (!serial.is_object()) return "the stored figures are not readable";
  if (held_scale_factor(serial)) return "";
  const json& ladders = serial.contains("ladders") ? serial["ladders"] : json();
  if (!ladders.is_array() || ladders.empty()) return "no rate_ladder step in the run";
  std::string why;
  for (const auto& l : ladders) {
    if (!l.is_object() || l.value("ok", false)) continue;
    why += fmt::format("{}{}: {}", why.empty() ? "" : "; ", l.value("label", "ladder"),
                       l.value("error", "not computed"));
  }
  return why.empty() ? "no ladder with a scale factor" : why;
}

std::string temperature_coefficient_missing(const json& serial) {
  if (!serial.is_object()) return "the stored figures are not readable";
  if (serial.contains("sf_vs_temp")) {
    const json& t = serial["sf_vs_temp"];
    if (t.is_object() && t.value("ok", false) && t.contains("tc_ppm_per_c")) return "";
    return t.is_object() ? t.value("error", "not computed") : "not computed";
  }
  int computed = 0;
  if (serial.contains("ladders") && serial["ladders"].is_array())
    for (const auto& l : serial["ladders"]) computed += l.is_object() && l.value("ok", false);
  if (computed == 0 && !scale_factor_missing(serial).empty()) return scale_factor_missing(serial);
  return fmt::format("{} ladder{} computed: a temperature coefficient needs two plateaus", computed,
                     computed == 1 ? "" : "s");
}

std::vector<AcceptancePoint> fleet_acceptance_points(PgConnection& pg, const ChartFilter& f) {
  // The part: the verdict's, else the one the run's slot named (a part without limits).
  auto r = pg.exec(
      "SELECT * FROM (SELECT r.fleet_id, r.station, a.serial, r.started_utc, a.computed_utc, "
      "coalesce(a.part_number, (SELECT s.part_number FROM run_slots AS s WHERE s.run_uuid = "
      "a.run_uuid AND s.serial = a.serial ORDER BY s.slot LIMIT 1)) AS part, a.pass, "
      "a.sf_pulse_per_arcsec, a.sf_se_pulse_per_arcsec, a.sf_temp_c, a.tc_ppm_per_c, "
      "a.tc_se_ppm_per_c, a.figures_json FROM acceptance_results AS a JOIN runs AS r ON r.uuid = "
      "a.run_uuid) AS x WHERE ($1::text IS NULL OR part = $1) AND ($2::text IS NULL OR "
      "started_utc >= $2) ORDER BY started_utc, fleet_id, serial",
      {f.part, f.since});
  std::vector<AcceptancePoint> out;
  for (int i = 0; i < r.rows(); ++i) {
    AcceptancePoint p;
    p.run_fleet_id = r.integer(i, 0);
    p.station = r.text(i, 1);
    p.serial = r.text(i, 2);
    p.run_started_utc = r.text(i, 3);
    p.computed_utc = r.text(i, 4);
    p.part = r.opt_text(i, 5).value_or(kNoPart);
    if (!r.is_null(i, 6)) p.pass = r.integer(i, 6) != 0;
    p.sf_pulse_per_arcsec = opt_number(r, i, 7);
    p.sf_se_pulse_per_arcsec = opt_number(r, i, 8);
    p.sf_temp_c = opt_number(r, i, 9);
    p.tc_ppm_per_c = opt_number(r, i, 10);
    p.tc_se_ppm_per_c = opt_number(r, i, 11);
    const json figures = json::parse(r.text(i, 12), nullptr, false);
    if (!p.sf_pulse_per_arcsec) p.sf_missing = scale_factor_missing(figures);
    if (!p.tc_ppm_per_c) p.tc_missing = temperature_coefficient_missing(figures);
    // A column empty while the figures say it was computed (a row edited by hand): still a why.
    if (!p.sf_pulse_per_arcsec && p.sf_missing.empty()) p.sf_missing = "not stored";
    if (!p.tc_ppm_per_c && p.tc_missing.empty()) p.tc_missing = "not stored";
    out.push_back(std::move(p));
  }
  read_turn_on_steps(pg, out);
  return out;
}

json fleet_acceptance_json(const std::vector<AcceptancePoint>& points) {
  std::map<std::string, std::vector<const AcceptancePoint*>> by_part;
  for (const auto& p : points) by_part[p.part].push_back(&p);
  json parts = json::array();
  for (const auto& [part, pts] : by_part) parts.push_back(part_json(part, pts));
  return {{"parts", parts}};
}

bool has_acceptance_table(PgConnection& pg) {
  return has_table(pg, "acceptance_results");
}

std::optional<std::vector<AcceptanceRow>> fleet_acceptance_rows_of_serial(
    PgConnection& pg, const std::string& serial) {
  if (!has_acceptance_table(pg)) return std::nullopt;
  auto r = pg.exec(
      "SELECT r.fleet_id, a.computed_utc, a.figures_json FROM acceptance_results AS a JOIN runs "
      "AS r ON r.uuid = a.run_uuid WHERE a.serial = $1 ORDER BY r.started_utc, r.fleet_id",
      {serial});
  std::vector<AcceptanceRow> rows;
  for (int i = 0; i < r.rows(); ++i) {
    const json figures = json::parse(r.text(i, 2), nullptr, false);
    if (figures.is_discarded() || !figures.is_object())
      throw PgError(
          fmt::format("PostgreSQL {}: acceptance_results of run {} serial '{}': the "
                      "stored figures are not readable JSON",
                      pg.where(), r.integer(i, 0), serial));
    rows.push_back(acceptance_row(r.integer(i, 0), figures));
    rows.back().computed_utc = r.text(i, 1);
  }
  return rows;
}

json fleet_acceptance_charts(PgConnection& pg, const ChartFilter& filter) {
  if (!has_acceptance_table(pg))
    return {{"parts", json::array()},
            {"unavailable",
             fmt::format("the fleet database (schema version {}) has no acceptance table yet: "
                         "migrate it with `station sync --init`",
                         server_schema_version(pg))}};
  return fleet_acceptance_json(fleet_acceptance_points(pg, filter));
}

std::string fleet_acceptance_text(const json& acceptance) {
  std::string out;
  if (acceptance.contains("unavailable"))
    out += fmt::format("acceptance figures: {}\n", acceptance["unavailable"].get<std::string>());
  for (const auto& part : acceptance["parts"]) {
    const auto& charts = part["charts"];
    out += fmt::format(
        "part {} acceptance: {} results at {} stations, K of {}, TC of {}, {} points beyond a "
        "limit\n",
        part["part"].get<std::string>(), part["results"].get<int>(), part["stations"].size(),
        charts[0]["points"].size(), charts[1]["points"].size(), part["outside"].size());
    for (const auto& r : part["results_list"]) {
      for (const auto& [key, name] : {std::pair{"sf_missing", "K"}, std::pair{"tc_missing", "TC"}})
        if (r[key].is_string())
          out += fmt::format("  {} not computed: {} {} run {} ({}): {}\n", name,
                             r["station"].get<std::string>(), r["serial"].get<std::string>(),
                             r["run_fleet_id"].get<long long>(),
                             r["run_started_utc"].get<std::string>(), r[key].get<std::string>());
      // The steps as turn_on_steps_json gave them: the keys turn_on_step_rows reads.
      for (const auto& t :
           turn_on_step_rows(json{{"turn_on_steps", r.value("turn_on_steps", json::array())}})) {
        const std::string name = turn_on_step_name(t);
        out += fmt::format("  turn-on {} {} run {}{}{}: {}\n", r["station"].get<std::string>(),
                           r["serial"].get<std::string>(), r["run_fleet_id"].get<long long>(),
                           name.empty() ? "" : " ", name, turn_on_step_text(t));
      }
    }
    for (const auto& o : part["outside"])
      out += fmt::format("  {} {} {} run {} ({}): {:.7g} {} beyond the {}\n",
                         o["metric"].get<std::string>(), o["station"].get<std::string>(),
                         o["serial"].get<std::string>(), o["run_fleet_id"].get<long long>(),
                         o["run_started_utc"].get<std::string>(), o["value"].get<double>(),
                         o["unit"].get<std::string>(), o["limit"].get<std::string>());
  }
  return out;
}

}  // namespace station::fleet
