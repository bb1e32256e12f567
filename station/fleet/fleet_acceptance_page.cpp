// The fleet page's acceptance sections (issue 36): per part the scale factor and its temperature
// coefficient across serials and runs, each point with its one-SE error bar, drawn as the thermal
// charts are (report::figure_html, the report's script and station/web/ticks.js).
#include <fmt/format.h>

#include <map>

#include "station/fleet/fleet_acceptance.hpp"
#include "station/report/report_pages.hpp"

namespace station::fleet {
namespace {

using nlohmann::json;
using report::html_escape;

std::string cells(std::initializer_list<std::string> c, const char* tag = "td") {
  std::string out = "<tr>";
  for (const auto& x : c) out += fmt::format("<{0}>{1}</{0}>", tag, x);
  return out + "</tr>\n";
}

/// "v ± se" in the figure's own precision, "-" without a value.
std::string pm(const json& v, const json& se, const char* spec) {
  if (!v.is_number()) return "-";
  std::string out = fmt::format(fmt::runtime(spec), v.get<double>());
  if (se.is_number()) out += fmt::format(" \u00b1 {:.2g}", se.get<double>());
  return out;
}

void add_point(report::Series& s, const json& p) {
  const double v = p["value"], se = p["se"].is_number() ? p["se"].get<double>() : 0.0;
  s.x.push_back(p["x"]);
  s.y.push_back(v);
  s.y_low.push_back(v - se);
  s.y_high.push_back(v + se);
}

/// One figure: a point series per station (whiskers: one standard error), K held at another
/// temperature as a series of its own, and the chart's centre line and limits.
report::Figure metric_figure(const json& chart, std::size_t part_index, double results,
                             double held_temp_c) {
  const std::string metric = chart["metric"], unit = chart["unit"];
  const bool k = metric == "K";
  const std::string axis = fmt::format("{} ({})", k ? "scale factor K" : "TC of K", unit);
  auto f = report::make_figure(
      fmt::format("acceptance-{}-{}", metric, part_index + 1),
      k ? fmt::format("Scale factor K held at {:g} C, error bars \u00b11 SE; limits X\u0304 "
                      "\u00b1 3\u03c3\u0302 (ISO 7870-2)",
                      held_temp_c)
        : std::string("Temperature coefficient of K, error bars \u00b11 SE; limits X\u0304 "
                      "\u00b1 3\u03c3\u0302 (ISO 7870-2)"),
      "acceptance result, in the order the runs started", axis);
  std::map<std::string, report::Series> by_station;
  report::Series apart;
  apart.label = fmt::format("K held at another temperature (see the table)");
  apart.whiskers = true;
  apart.large_points = true;
  for (const auto& p : chart["points"]) {
    if (!p["in_limits_chart"].get<bool>() && k) {
      add_point(apart, p);
      continue;
    }
    auto& s = by_station[p["station"]];
    s.label = p["station"];
    s.whiskers = true;
    add_point(s, p);
  }
  for (auto& [name, s] : by_station) f.series.push_back(std::move(s));
  if (!apart.x.empty()) f.series.push_back(std::move(apart));
  if (const auto& o = chart["overall"]; o.is_object()) {
    const std::pair<const char*, const char*> kLines[] = {
        {"ucl", "UCL"}, {"centre", "centre"}, {"lcl", "LCL"}};
    for (const auto& [key, label] : kLines) {
      report::Series line;
      line.label = label;
      line.x = {1.0, results};
      line.y = {o[key].get<double>(), o[key].get<double>()};
      line.line = true;
      f.series.push_back(std::move(line));
    }
  } else {
    f.note = "fewer than two results of one station: no control limits (ISO 7870-2)";
  }
  return f;
}

/// A result's power_cycles steps, one line each: "'warm' (step 12, 35.0 C): sigma ...".
std::string turn_on_cell(const json& result) {
  std::string t;
  for (const auto& s :
       turn_on_step_rows(json{{"turn_on_steps", result.value("turn_on_steps", json::array())}})) {
    const std::string name = turn_on_step_name(s);
    t += (t.empty() ? "" : "<br>") +
         html_escape((name.empty() ? "" : name + ": ") + turn_on_step_text(s));
  }
  return t.empty() ? "-" : t;
}

std::string results_table(const json& part) {
  std::string t =
      "<table class=\"acceptance-results\">\n" +
      cells({"result (place)", "station", "serial", "run (fleet id)", "run started (UTC)",
             "K \u00b1 SE (pulse/arcsec)", "K held at (C)", "TC \u00b1 SE (ppm/C)",
             "turn-on \u03c3 per power_cycles step (deg/h)", "acceptance verdict"},
            "th");
  for (const auto& r : part["results_list"]) {
    const std::string k = r["sf_missing"].is_string()
                              ? "<span class=\"missing\">not computed: " +
                                    html_escape(r["sf_missing"].get<std::string>()) + "</span>"
                              : pm(r["sf_pulse_per_arcsec"], r["sf_se_pulse_per_arcsec"], "{:.7f}");
    const std::string tc = r["tc_missing"].is_string()
                               ? "<span class=\"missing\">not computed: " +
                                     html_escape(r["tc_missing"].get<std::string>()) + "</span>"
                               : pm(r["tc_ppm_per_c"], r["tc_se_ppm_per_c"], "{:+.3f}");
    const std::string verdict = r["pass"].is_boolean()
                                    ? (r["pass"].get<bool>() ? "<span class=\"pass\">PASS</span>"
                                                             : "<span class=\"fail\">FAIL</span>")
                                    : std::string("not judged (no acceptance limits)");
    t += cells(
        {std::to_string(r["x"].get<int>()), html_escape(r["station"].get<std::string>()),
         html_escape(r["serial"].get<std::string>()),
         std::to_string(r["run_fleet_id"].get<long long>()),
         html_escape(r["run_started_utc"].get<std::string>()), k,
         r["sf_temp_c"].is_number() ? fmt::format("{:.1f}", r["sf_temp_c"].get<double>()) : "-", tc,
         turn_on_cell(r), verdict});
  }
  return t + "</table>\n";
}

}  // namespace

std::string fleet_acceptance_html(const json& acceptance, json& figures) {
  std::string body;
  if (acceptance.contains("unavailable"))
    body += "<p class=\"acceptance-unavailable\">acceptance figures: " +
            html_escape(acceptance["unavailable"].get<std::string>()) + "</p>\n";
  std::size_t i = 0;
  for (const auto& part : acceptance["parts"]) {
    body += fmt::format(
        "<section class=\"acceptance\" data-part=\"{}\">\n<h2>part {}: acceptance, {} results "
        "at {} stations</h2>\n",
        html_escape(part["part"].get<std::string>()), html_escape(part["part"].get<std::string>()),
        part["results"].get<int>(), part["stations"].size());
    const double results = part["results"].get<double>();
    for (const auto& c : part["charts"]) {
      if (c["points"].empty()) {
        body += fmt::format(
            "<p class=\"no-chart\" data-metric=\"{0}\">{0}: no result of this part has it (the "
            "table says why), no chart.</p>\n",
            html_escape(c["metric"].get<std::string>()));
        continue;
      }
      const auto f = metric_figure(c, i, results, part["held_temp_c"].get<double>());
      body += report::figure_html(f);
      auto j = report::figure_json(f);
      // Results 1..n with half a place either side (as the thermal charts).
      j["options"]["dateWindow"] = {0.5, results + 0.5};
      figures.push_back(std::move(j));
    }
    body += "<h3>Results</h3>\n" + results_table(part) + "</section>\n";
    ++i;
  }
  if (acceptance["parts"].empty())
    body += "<p class=\"empty-acceptance\">No acceptance result matches.</p>\n";
  return body;
}

}  // namespace station::fleet
