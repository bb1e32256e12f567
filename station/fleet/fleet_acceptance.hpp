// The acceptance figures across the fleet (`station fleet`, issue 36): per part number, each
// run's scale factor K (held to 25 C, with its standard error) and its temperature coefficient
// (ppm/C, with its standard error), serial by serial in the order the runs started, with the
// fleet's individuals chart (compensation/control_chart.hpp, ISO 7870-2) of each; a result
// without a figure says why (its ladders' own errors), never a zero. Read from the central
// acceptance_results (fleet schema version 6) and the runs they belong to.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "station/fleet/fleet_charts.hpp"
#include "station/fleet/pg.hpp"
#include "station/store/acceptance_results.hpp"

namespace station::fleet {

/// One serial's acceptance result of one run, as the fleet charts it.
struct AcceptancePoint {
  std::int64_t run_fleet_id = 0;
  std::string station, serial, run_started_utc, computed_utc, part;
  std::optional<bool> pass;  ///< the acceptance verdict; empty: the part had no limits
  std::optional<double> sf_pulse_per_arcsec, sf_se_pulse_per_arcsec, sf_temp_c;
  std::optional<double> tc_ppm_per_c, tc_se_ppm_per_c;
  std::string sf_missing, tc_missing;  ///< why K / TC is not there (empty when it is)
  /// Every power_cycles step's turn-on figures (fleet schema 7; empty on a server before it).
  std::vector<TurnOnStepRow> turn_on_steps;
};

/// Why a serial's object (acceptance_json, as stored) has no held scale factor: "no rate_ladder
/// step in the run", or each ladder's label and error; empty when it has one.
std::string scale_factor_missing(const nlohmann::json& serial);
/// Why it has no temperature coefficient: the fit's own error, or how many ladders were computed
/// (the fit needs two plateaus); empty when it has one.
std::string temperature_coefficient_missing(const nlohmann::json& serial);

/// The stored results from the central database, in the order their runs started. `filter`:
/// the part (the verdict's, else the slot's), and runs started at or after `since`.
std::vector<AcceptancePoint> fleet_acceptance_points(PgConnection& pg, const ChartFilter& filter);

/// The charts per part as JSON: {"parts": [{"part", "results", "stations", "verdicts",
/// "held_temp_c", "charts": [{"metric": "K" | "TC", "unit", "overall", "points": [{"x",
/// "station", "serial", "run_fleet_id", "run_started_utc", "value", "se", "held_temp_c"?,
/// "outside_overall"}]}], "results_list": [...every result, with "sf_missing" / "tc_missing" and
/// "turn_on_steps" (turn_on_steps_json: each power_cycles step's sigma and warm-up)],
/// "outside"}]}. x: the result's place among the part's results (1..n, the same in both charts);
/// the chart's limits over the K held within 1 C of 25 C only (another temperature is another
/// quantity; such points are drawn apart and named).
nlohmann::json fleet_acceptance_json(const std::vector<AcceptancePoint>& points);

/// The acceptance part of `station fleet`'s charts: fleet_acceptance_json of the server's
/// results, or, on a server whose schema predates the acceptance table (fleet schema < 6: a
/// fleet not migrated since), {"parts": [], "unavailable": why} — the thermal charts stay
/// drawable on such a server.
nlohmann::json fleet_acceptance_charts(PgConnection& pg, const ChartFilter& filter);

/// One serial's acceptance rows on the server (`station history --pg`), oldest run first, each
/// row's run_id the fleet's id of its run and its columns read from its figures as the station
/// read them (acceptance_row); empty when the server has no acceptance table (schema < 6).
std::optional<std::vector<AcceptanceRow>> fleet_acceptance_rows_of_serial(
    PgConnection& pg, const std::string& serial);

/// The page's acceptance sections: per part the K and TC figures (report::figure_html, error
/// bars of one standard error) and the table of results; appends the figures' JSON to `figures`.
std::string fleet_acceptance_html(const nlohmann::json& acceptance, nlohmann::json& figures);

/// The text output: per part one line of counts, then each result without K or TC and why, each
/// result's turn-on figures per power_cycles step, and each point beyond a limit.
std::string fleet_acceptance_text(const nlohmann::json& acceptance);

}  // namespace station::fleet
