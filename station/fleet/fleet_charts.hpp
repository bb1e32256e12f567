// Control charts across the fleet (`station fleet`): per part number, an individuals chart
// (compensation/control_chart.hpp, ISO 7870-2) of k1, k0, B0 and the std ratio over the
// calibrations in time order, for the whole fleet and per station, the verdicts per station, and
// every point beyond a limit. A calibration is the newest fit of one set of runs with one set of
// terms at one station (a refit is not a new calibration; station/parts/history.hpp).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compensation/control_chart.hpp"
#include "station/fleet/pg.hpp"

namespace station::fleet {

/// One calibration as the charts use it.
struct FleetPoint {
  std::int64_t fleet_id = 0;
  std::string station, serial, created_utc, part;
  std::string terms;      ///< the fitted model: a chart never mixes models
  double ref_temp_c = 0;  ///< T_ref of the fit: k1 and B0 mean something else at another
  std::optional<double> k1, k0, b0, std_ratio;
  std::optional<bool> pass;  ///< the verdict; empty: none
};

struct ChartFilter {
  std::optional<std::string> part;   ///< only this part number
  std::optional<std::string> since;  ///< only calibrations created at or after (ISO-8601 text)
};

/// Calibrations from the central database, oldest first.
std::vector<FleetPoint> fleet_points(PgConnection& pg, const ChartFilter& filter);

/// The charts of every part and model among `points` as JSON: {"parts": [{"part", "terms",
/// "ref_temp_c", "calibrations", "stations", "charts": [{"metric", "unit", "overall",
/// "by_station", "points"}], "verdicts", "outside"}]}. The overall chart's σ̂ pools the moving
/// ranges within each station (compensation::individuals_chart with groups).
nlohmann::json fleet_charts_json(const std::vector<FleetPoint>& points);

/// What tells one chart set of `fleet_charts_json` from another, as its text says it: "part
/// GX-200, model B0+dT+gradT, T_ref 25 C" (two sets of one part differ in model or T_ref).
std::string chart_set_title(const nlohmann::json& part);

/// The part label of a calibration without a part number.
inline constexpr const char* kNoPart = "(no part)";

}  // namespace station::fleet
