// HTML building blocks of the report: escaping, figure data for dygraphs, the page shell.
#include "station/report/report_html.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "station/common/input_error.hpp"
#include "station/report/report_pages.hpp"
#include "station/web/builtin_web.hpp"

namespace station::report {

using nlohmann::json;
namespace {

std::string read_package_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(fmt::format(
        "{}: cannot read the charting library (install the Debian package libjs-dygraphs)", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The live page's tick script (station/web/ticks.js, embedded at build time): one ticker for
/// both.
std::string_view ticks_js() {
  for (const auto& [name, text] : builtin::kWebFiles)
    if (name == "ticks.js") return text;
  throw std::logic_error("ticks.js is not embedded (station/CMakeLists.txt)");
}

/// Per-series dygraphs options: lines, or points only (a scatter plot), and the axis.
json series_options(const Series& s) {
  json o = s.line ? json{{"strokeWidth", 1.5}, {"drawPoints", false}}
                  : json{{"strokeWidth", 0.0}, {"drawPoints", true}, {"pointSize", 2}};
  if (s.second_y) o["axis"] = "y2";
  if (s.whiskers) o["whiskers"] = true;  // the page's script (report_script.cpp) draws them
  if (s.large_points) o["pointSize"] = 4;
  return o;
}

json figure_options(const Figure& f, bool bars) {
  json labels = json::array({f.x_label}), series = json::object();
  for (const auto& s : f.series) {
    labels.push_back(s.label);
    series[s.label] = series_options(s);
  }
  json o{{"labels", labels},
         {"xlabel", f.x_label},
         {"ylabel", f.y_label},
         {"series", series},
         {"connectSeparatedPoints", true},
         {"legend", "always"},
         {"customBars", bars},
         {"sigFigs", 4}};
  // Ticks and label widths: the page's script (report_script.cpp) sets them for each axis.
  o["axes"] = json::object();
  // The value ranges: padded around the data by the page's script (StationTicks.padded).
  if (!f.y2_label.empty()) o["y2label"] = f.y2_label;
  if (f.log_axes) {
    o["logscale"] = true;
    o["axes"]["x"] = {{"logscale", true}};
  }
  return o;
}

}  // namespace

Assets read_dygraphs(const std::string& dir) {
  return {read_package_file(dir + "/dygraph.min.js"), read_package_file(dir + "/dygraph.min.css")};
}

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string script_json(const json& j) {
  const std::string text = j.dump(-1, ' ', false, json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  // <, > and & only occur inside JSON strings, where \u003c etc. mean the same character; none
  // is left to close the <script> element ("</script>") or open a comment ("<!--").
  for (const char c : text) {
    if (c == '<')
      out += "\\u003c";
    else if (c == '>')
      out += "\\u003e";
    else if (c == '&')
      out += "\\u0026";
    else
      out += c;
  }
  return out;
}

json figure_json(const Figure& f) {
  bool bars = false;
  for (const auto& s : f.series) bars = bars || !s.y_low.empty();
  // Rows sorted by x, a column per series, null where a series has no point: the n-th point of
  // each series at an x shares row (x, n), so a series' repeated x is a row more, never lost.
  std::map<std::pair<double, int>, json> rows;
  for (std::size_t k = 0; k < f.series.size(); ++k) {
    const auto& s = f.series[k];
    std::map<double, int> seen;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      auto [it, fresh] = rows.try_emplace({s.x[i], seen[s.x[i]]++}, json::array());
      if (fresh) {
        it->second.push_back(s.x[i]);
        for (std::size_t n = 0; n < f.series.size(); ++n) it->second.push_back(nullptr);
      }
      // With bars on, dygraphs reads every value as [low, y, high]: a series without an
      // interval (Fig. 5b's fitted curves) is its value thrice, else it is not drawn.
      it->second[k + 1] = !bars              ? json(s.y[i])
                          : !s.y_low.empty() ? json::array({s.y_low[i], s.y[i], s.y_high[i]})
                                             : json::array({s.y[i], s.y[i], s.y[i]});
    }
  }
  json data = json::array();
  for (auto& [x, row] : rows) data.push_back(std::move(row));
  return {{"id", f.id},
          {"points", f.points()},
          {"rows", std::move(data)},
          {"options", figure_options(f, bars)}};
}

std::string page_html(std::string_view title, std::string_view body, const json& figures,
                      const Assets& a) {
  return fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>{}</title>\n<style>\n{}\n</style>\n<style>\n{}\n</style>\n"
      "<script>\n{}\n</script>\n</head>\n<body>\n{}\n"
      "<script type=\"application/json\" id=\"report-figures\">{}</script>\n"
      "<script>\n{}\n{}\n</script>\n</body>\n</html>\n",
      html_escape(title), a.dygraphs_css, kReportCss, a.dygraphs_js, body, script_json(figures),
      ticks_js(), kRenderJs);
}

}  // namespace station::report
