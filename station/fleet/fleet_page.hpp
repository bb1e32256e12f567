// `station fleet --out DIR`: the control charts as one self-contained HTML page, drawn like the
// run report (dygraphs inlined, figures as JSON; station/report/report_pages.hpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "station/report/report_html.hpp"

namespace station::fleet {

/// The page of `charts` (fleet_charts_json); `filter_text` says what was selected.
std::string fleet_html(const nlohmann::json& charts, const std::string& filter_text,
                       const report::Assets& assets);

}  // namespace station::fleet
