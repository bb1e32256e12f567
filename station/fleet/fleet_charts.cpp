#include "station/fleet/fleet_charts.hpp"

#include <fmt/format.h>

#include <map>
#include <tuple>

#include "compensation/fit.hpp"

namespace station::fleet {
namespace {

using nlohmann::json;
namespace sc = station::compensation;

std::optional<double> coefficient(const json& c, const char* name) {
  const auto it = c.find(name);
  return it != c.end() && it->is_number() ? std::optional(it->get<double>()) : std::nullopt;
}

FleetPoint point_of(const PgResult& r, int i) {
  FleetPoint p;
  p.fleet_id = r.integer(i, 0);
  p.station = r.text(i, 1);
  p.serial = r.text(i, 2);
  p.created_utc = r.text(i, 3);
  p.part = r.opt_text(i, 4).value_or(kNoPart);
  const json c = json::parse(r.text(i, 5), nullptr, false);
  p.k1 = coefficient(c, "k1");
  p.k0 = coefficient(c, "k0");
  p.b0 = coefficient(c, "B0");
  if (!r.is_null(i, 6)) p.std_ratio = r.number(i, 6);
  p.terms = r.text(i, 8);
  p.ref_temp_c = r.number(i, 9);
  if (auto v = r.opt_text(i, 7)) {
    const json j = json::parse(*v, nullptr, false);
    if (j.is_object() && j.contains("pass")) p.pass = j["pass"].get<bool>();
  }
  return p;
}

/// The points of one metric that have it, with their values.
struct Metric {
  const char* name;
  const char* unit;
  std::optional<double> FleetPoint::*field;
};
// Coefficient units as the fit names them (compensation/fit.hpp); the std ratio has none.
const Metric kMetrics[] = {{"k1", nullptr, &FleetPoint::k1},
                           {"k0", nullptr, &FleetPoint::k0},
                           {"B0", nullptr, &FleetPoint::b0},
                           {"std_ratio", "1", &FleetPoint::std_ratio}};

std::string unit_of(const Metric& m) {
  return m.unit != nullptr ? m.unit : std::string(sc::coefficient_unit(m.name));
}

json chart_json(const std::optional<sc::IndividualsChart>& c) {
  if (!c) return nullptr;
  return {{"n", c->n},         {"centre", c->centre}, {"mr_bar", c->mr_bar},
          {"sigma", c->sigma}, {"lcl", c->lcl},       {"ucl", c->ucl}};
}

const char* side(const sc::IndividualsChart& c, double v) {
  return v > c.ucl ? "UCL" : "LCL";
}

json metric_json(const Metric& m, const std::vector<const FleetPoint*>& points, json& outside) {
  std::vector<const FleetPoint*> have;
  std::vector<double> all;
  std::vector<int> group;
  std::map<std::string, int> station_index;
  std::map<std::string, std::vector<double>> by_station;
  for (const auto* p : points) {
    if (!(p->*m.field)) continue;
    have.push_back(p);
    all.push_back(*(p->*m.field));
    group.push_back(station_index.try_emplace(p->station, static_cast<int>(station_index.size()))
                        .first->second);
    by_station[p->station].push_back(*(p->*m.field));
  }
  const auto overall = sc::individuals_chart(all, group);
  std::map<std::string, std::optional<sc::IndividualsChart>> station_charts;
  json js = json::object();
  for (const auto& [s, v] : by_station) {
    station_charts[s] = sc::individuals_chart(v);
    js[s] = chart_json(station_charts[s]);
  }
  json jp = json::array();
  for (std::size_t i = 0; i < have.size(); ++i) {
    const auto* p = have[i];
    const double v = all[i];
    const auto& sc_chart = station_charts[p->station];
    const bool out_all = overall && overall->sigma > 0 && (v < overall->lcl || v > overall->ucl);
    const bool out_station =
        sc_chart && sc_chart->sigma > 0 && (v < sc_chart->lcl || v > sc_chart->ucl);
    jp.push_back({{"fleet_id", p->fleet_id},
                  {"station", p->station},
                  {"serial", p->serial},
                  {"created_utc", p->created_utc},
                  {"value", v},
                  {"outside_overall", out_all},
                  {"outside_station", out_station}});
    if (out_all || out_station) {
      outside.push_back({{"metric", m.name},
                         {"unit", unit_of(m)},
                         {"fleet_id", p->fleet_id},
                         {"station", p->station},
                         {"serial", p->serial},
                         {"created_utc", p->created_utc},
                         {"value", v},
                         {"chart", out_all ? "overall" : "station"},
                         {"limit", side(out_all ? *overall : *sc_chart, v)}});
    }
  }
  return {{"metric", m.name},
          {"unit", unit_of(m)},
          {"overall", chart_json(overall)},
          {"by_station", js},
          {"points", jp}};
}

json part_json(const std::vector<const FleetPoint*>& points) {
  json charts = json::array(), outside = json::array(), verdicts = json::object();
  std::map<std::string, int> stations;
  for (const auto* p : points) {
    ++stations[p->station];
    auto& v = verdicts[p->station];
    if (v.is_null()) v = {{"pass", 0}, {"fail", 0}, {"none", 0}};
    const char* k = !p->pass ? "none" : *p->pass ? "pass" : "fail";
    v[k] = v[k].get<int>() + 1;
  }
  for (const auto& m : kMetrics) charts.push_back(metric_json(m, points, outside));
  const FleetPoint& first = *points.front();
  return {{"part", first.part},
          {"terms", first.terms},
          {"ref_temp_c", first.ref_temp_c},
          {"calibrations", points.size()},
          {"stations", stations},
          {"charts", charts},
          {"verdicts", verdicts},
          {"outside", outside}};
}

}  // namespace

std::vector<FleetPoint> fleet_points(PgConnection& pg, const ChartFilter& f) {
  auto r = pg.exec(
      "SELECT fleet_id, station, serial, created_utc, part_number, coefficients_json, std_ratio, "
      "verdict_json, terms, ref_temp_c FROM (SELECT DISTINCT ON (station, serial, run_uuids_json, "
      "terms) * FROM fits "
      "WHERE ($1::text IS NULL OR part_number = $1) AND ($2::text IS NULL OR created_utc >= $2) "
      "ORDER BY station, serial, run_uuids_json, terms, created_utc DESC, fleet_id DESC) AS c "
      "ORDER BY created_utc, fleet_id",
      {f.part, f.since});
  std::vector<FleetPoint> out;
  for (int i = 0; i < r.rows(); ++i) out.push_back(point_of(r, i));
  return out;
}

std::string chart_set_title(const json& part) {
  return fmt::format("part {}, model {}, T_ref {:g} C", part["part"].get<std::string>(),
                     part["terms"].get<std::string>(), part["ref_temp_c"].get<double>());
}

json fleet_charts_json(const std::vector<FleetPoint>& points) {
  // One chart set per part and model: k1 of another model or another T_ref is another quantity.
  std::map<std::tuple<std::string, std::string, double>, std::vector<const FleetPoint*>> by_part;
  for (const auto& p : points) by_part[{p.part, p.terms, p.ref_temp_c}].push_back(&p);
  json parts = json::array();
  for (const auto& [key, pts] : by_part) parts.push_back(part_json(pts));
  return {{"parts", parts}};
}

}  // namespace station::fleet
