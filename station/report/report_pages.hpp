// Inside the report room: the page shell and the sections the index and serial pages share.
#pragma once

#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "station/report/report_html.hpp"

namespace station::report {

/// The report's own style sheet (after dygraphs').
extern const std::string_view kReportCss;
/// The page's script (after station/web/ticks.js): parses #report-figures and hands each figure
/// to Dygraph with round ticks; marks its element data-drawn="true" once drawn with room for its
/// labels. No data is ever written into it.
extern const std::string_view kRenderJs;

/// `v` formatted by `spec`, "-" when not finite (or empty).
std::string num(double v, const char* spec = "{:.5g}");
std::string num(const std::optional<double>& v, const char* spec = "{:.5g}");
/// A table row of cells (already escaped HTML).
std::string row(std::initializer_list<std::string> cells);
/// A row whose first cell heads it (names the quantity and its unit).
std::string kv(const std::string& head, std::initializer_list<std::string> cells);

/// A whole page: `body` (already escaped HTML), the figures as JSON, dygraphs inlined.
std::string page_html(std::string_view title, std::string_view body, const nlohmann::json& figures,
                      const Assets& a);

/// A figure's box: title, chart and legend elements kRenderJs draws into, and its note.
std::string figure_html(const Figure& f);

/// The verdict for people: "PASS", "FAIL: limit value (bound b); ..." or "no verdict".
std::string verdict_text(const FitExtras& e);

/// <section> with the run record: station, software, configuration hash, operator, protocol,
/// state, start and end.
std::string run_record_html(const RunReport& r);

/// Whether the run's own fit is the gyro's calibration, was superseded, or was never released;
/// a released fit other than the run's named with its model (report_release.cpp).
std::string release_html(const SerialReport& s);

/// The index's release cell of a serial.
std::string release_cell(const SerialReport& s);

/// <section> with every other fit that used the run (later refits, other models), dated, each
/// with its model and release; empty when there is none.
std::string other_fits_html(const SerialReport& s);

/// <section> with the run's events in order.
std::string events_html(const RunReport& r);

}  // namespace station::report
