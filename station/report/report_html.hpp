// The report's HTML pages: self-contained files (dygraphs inlined from the Debian package
// libjs-dygraphs, figure data as JSON in <script type="application/json">) that open from disk
// with no network.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "station/report/report_data.hpp"
#include "station/report/report_load.hpp"

namespace station::report {

/// Where Debian's libjs-dygraphs installs the library.
inline constexpr std::string_view kDygraphsDir = "/usr/share/javascript/dygraphs";

/// The charting library, read at report time (never a copy in this repository).
struct Assets {
  std::string dygraphs_js, dygraphs_css;
};

/// Reads dygraph.min.js and dygraph.min.css from `dir`; throws InputError naming the missing
/// file and the package that provides it.
Assets read_dygraphs(const std::string& dir);

/// `text` with & < > " ' as character references: safe as HTML text and attribute values.
std::string html_escape(std::string_view text);

/// `j` as JSON that cannot end or comment its <script> element: every <, > and & inside a
/// string as a \u escape. Invalid UTF-8 from the database is replaced, never thrown on.
std::string script_json(const nlohmann::json& j);

/// A figure as dygraphs takes it: {"id", "points", "rows": [[x, y or null or [low, y, high],
/// ...]], "options": {labels, xlabel, ylabel, series, ...}}; rows sorted by x.
nlohmann::json figure_json(const Figure& f);

/// The run's index page: run record, every serial's verdict and summary, events; `pages[i]` is
/// the file name of serial i's page (empty: none).
std::string index_html(const RunReport& r, const Assets& a, const std::vector<std::string>& pages);

/// The index's section linking the run's acceptance pages; empty without acceptance steps.
std::string acceptance_index_html(const RunReport& r);

/// An acceptance page of the run (report_acceptance.hpp): per serial its figures' table and
/// figures, then the run record.
std::string acceptance_html(const RunReport& r, AcceptancePage p, const Assets& a);

/// One serial's page: verdict, coefficient table, noise terms, Figs. 2a-5b, run record, events.
std::string serial_html(const RunReport& r, const SerialReport& s, const Assets& a);

}  // namespace station::report
