#include "station/fleet/fleet_page.hpp"

#include <fmt/format.h>

#include <map>

#include "station/fleet/fleet_acceptance.hpp"
#include "station/fleet/fleet_charts.hpp"
#include "station/report/report_pages.hpp"

namespace station::fleet {
namespace {

using nlohmann::json;
using report::html_escape;

std::string num(const json& v) {
  return v.is_number() ? fmt::format("{:.4g}", v.get<double>()) : "-";
}

std::string cells(std::initializer_list<std::string> c, const char* tag = "td") {
  std::string out = "<tr>";
  for (const auto& x : c) out += fmt::format("<{0}>{1}</{0}>", tag, x);
  return out + "</tr>\n";
}

/// One metric's chart: a point series per station at its place in time order, and the fleet's
/// centre line and control limits.
report::Figure metric_figure(const json& chart, std::size_t part_index) {
  const std::string metric = chart["metric"], unit = chart["unit"];
  const std::string axis = unit == "1" ? metric : fmt::format("{} ({})", metric, unit);
  auto f =
      report::make_figure(fmt::format("{}-{}", metric, part_index + 1),
                          fmt::format("{}: individuals chart, limits X\u0304 \u00b1 3\u03c3\u0302 "
                                      "(ISO 7870-2)",
                                      axis),
                          "calibration, in time order", axis);
  std::map<std::string, report::Series> by_station;
  double x = 0;
  for (const auto& p : chart["points"]) {
    auto& s = by_station[p["station"]];
    s.label = p["station"];
    s.x.push_back(++x);
    s.y.push_back(p["value"]);
  }
  for (auto& [name, s] : by_station) f.series.push_back(std::move(s));
  if (const auto& o = chart["overall"]; o.is_object() && x >= 1) {
    const std::pair<const char*, const char*> kLines[] = {
        {"ucl", "UCL"}, {"centre", "centre"}, {"lcl", "LCL"}};
    for (const auto& [key, label] : kLines) {
      report::Series line;
      line.label = label;
      line.x = {1.0, x};
      line.y = {o[key].get<double>(), o[key].get<double>()};
      line.line = true;
      f.series.push_back(std::move(line));
    }
  }
  if (x == 1) f.note = "one calibration: no control limits (they need two, ISO 7870-2)";
  return f;
}

std::string station_table(const json& part) {
  std::string t = "<table class=\"stations\">\n" +
                  cells({"station", "calibrations (count)", "pass (count)", "fail (count)",
                         "no verdict (count)", "k1 centre (deg/h/C)", "k0 centre (deg/h/C)",
                         "B0 centre (deg/h)", "std ratio centre (after / before)"},
                        "th");
  for (const auto& [station, n] : part["stations"].items()) {
    const auto& v = part["verdicts"][station];
    std::vector<std::string> centres;
    for (const auto& c : part["charts"]) {
      const auto& s = c["by_station"].contains(station) ? c["by_station"][station] : json();
      centres.push_back(s.is_object() ? num(s["centre"]) : "-");
    }
    t += cells({html_escape(station), std::to_string(n.get<int>()),
                std::to_string(v["pass"].get<int>()), std::to_string(v["fail"].get<int>()),
                std::to_string(v["none"].get<int>()), centres[0], centres[1], centres[2],
                centres[3]});
  }
  return t + "</table>\n";
}

std::string outside_table(const json& part) {
  if (part["outside"].empty())
    return "<p class=\"outside-none\">No point beyond a control limit.</p>\n";
  std::string t = "<table class=\"outside\">\n" +
                  cells({"metric", "station", "serial", "fit (fleet id)", "created (UTC)",
                         "value (the metric's unit)", "chart", "limit"},
                        "th");
  for (const auto& o : part["outside"])
    t += cells(
        {html_escape(o["metric"].get<std::string>()), html_escape(o["station"].get<std::string>()),
         html_escape(o["serial"].get<std::string>()),
         std::to_string(o["fleet_id"].get<long long>()),
         html_escape(o["created_utc"].get<std::string>()),
         num(o["value"]) + " " + html_escape(o["unit"].get<std::string>()),
         html_escape(o["chart"].get<std::string>()), html_escape(o["limit"].get<std::string>())});
  return t + "</table>\n";
}

/// `station fleet --propose-noise`: one row per part, its block to paste (noise_proposal.hpp).
std::string noise_section(const json& noise) {
  std::string t =
      "<section class=\"noise\">\n<h2>The parts' noise proposed from their runs</h2>\n"
      "<p>IEEE 952 terms fitted to each run's compensated 1 Hz record; per part the median over "
      "its usable runs and a trust factor from their spread (README, <em>The part's "
      "noise</em>).</p>\n<table class=\"noise\">\n" +
      cells(
          {"part", "runs (usable / all)", "stations (count)", "serials (count)", "N (deg/sqrt(h))",
           "B (deg/h)", "K (deg/h/sqrt(h))", "trust factor (x/)", "part-file block"},
          "th");
  for (const auto& p : noise) {
    std::vector<std::string> v;
    for (const auto& term : p["terms"]) v.push_back(num(term["value"]));
    t += cells({html_escape(p["part"].get<std::string>()),
                fmt::format("{} / {}", p["usable_runs"].get<int>(), p["runs"].get<int>()),
                std::to_string(p["stations"].get<int>()), std::to_string(p["serials"].get<int>()),
                v[0], v[1], v[2], num(p["trust_factor"]),
                "<pre>" + html_escape(p["toml"].get<std::string>()) + "</pre>"});
  }
  return t + "</table>\n</section>\n";
}

}  // namespace

std::string fleet_html(const json& charts, const std::string& filter_text,
                       const report::Assets& assets) {
  std::string body = fmt::format(
      "<h1>Fleet control charts</h1>\n<p class=\"filter\">{}</p>\n"
      "<p>Individuals charts (ISO 7870-2), one colour per station: centre X\u0304 over the whole "
      "fleet, \u03c3\u0302 = MR\u0304 / 1.128 from the moving ranges between consecutive "
      "calibrations of one station (so an offset between stations shows beyond the limits "
      "instead of widening them), limits X\u0304 \u00b1 3\u03c3\u0302; each station's own "
      "chart is in the JSON (--json).</p>\n",
      html_escape(filter_text));
  json figures = json::array();
  std::size_t i = 0;
  for (const auto& part : charts["parts"]) {
    body += fmt::format(  // the set's title as the text output names it (chart_set_title)
        "<section class=\"part\" data-part=\"{}\">\n<h2>{}: {} calibrations at {} stations</h2>\n",
        html_escape(part["part"].get<std::string>()), html_escape(chart_set_title(part)),
        part["calibrations"].get<int>(), part["stations"].size());
    body += station_table(part);
    for (const auto& c : part["charts"]) {
      if (c["points"].empty()) {  // a coefficient this model does not have: no empty chart
        body += fmt::format(
            "<p class=\"no-chart\" data-metric=\"{0}\">{0}: not a term of "
            "model {1}, no chart.</p>\n",
            html_escape(c["metric"].get<std::string>()),
            html_escape(part["terms"].get<std::string>()));
        continue;
      }
      const auto f = metric_figure(c, i);
      body += report::figure_html(f);
      auto j = report::figure_json(f);
      // Calibrations 1..n with half a place either side: the first and last off the corners,
      // and one calibration in the middle, not on the axis.
      j["options"]["dateWindow"] = {0.5, static_cast<double>(c["points"].size()) + 0.5};
      figures.push_back(std::move(j));
    }
    body += "<h3>Points beyond a limit</h3>\n" + outside_table(part) + "</section>\n";
    ++i;
  }
  if (charts["parts"].empty()) body += "<p class=\"empty\">No calibration matches.</p>\n";
  if (charts.contains("acceptance")) body += fleet_acceptance_html(charts["acceptance"], figures);
  if (charts.contains("noise")) body += noise_section(charts["noise"]);
  return report::page_html("Fleet control charts", body, figures, assets);
}

}  // namespace station::fleet
