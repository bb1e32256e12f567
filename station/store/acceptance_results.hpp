// A run's acceptance figures as stored (migration 12, issue 36): one row per (run, serial), the
// figures compared across runs as columns and the serial's whole object (acceptance_json with its
// verdict) as JSON. Computed and written by station/acceptance/acceptance_record.hpp; read by the
// API, `history`, `fit` and the end summary.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// The scale factor a serial is held to (its verdict, its row, history's drift): K at the
/// reference temperature of the temperature model over its ladders, else its one ladder's K at
/// that ladder's temperature.
struct HeldScaleFactor {
  double k_pulse_per_arcsec = 0, se_pulse_per_arcsec = 0;
  std::optional<double> temp_c;  ///< where K holds, C; empty when its ladder had no temperature
};
/// Where a scale factor without a temperature model is taken: the ladder nearest this, C.
inline constexpr double kHeldScaleFactorTempC = 25.0;
/// Two K held further apart than this are two quantities (each carries TC times the gap): history
/// names the gap instead of a drift, the fleet charts such a K apart from the limits' K, C.
inline constexpr double kHeldTempToleranceC = 1.0;
/// HeldScaleFactor of one serial's object (acceptance_json): K at T_ref of the fit across the
/// plateaus; without one (a single ladder, or plateaus too close), the computed ladder nearest
/// kHeldScaleFactorTempC at its temperature; empty when no ladder was computed.
std::optional<HeldScaleFactor> held_scale_factor(const nlohmann::json& serial);

/// One stored row.
struct AcceptanceRow {
  std::int64_t run_id = 0;
  std::string serial, computed_utc;
  std::optional<std::string> part_number;  ///< the verdict's part; empty: not judged
  std::optional<bool> pass;
  std::optional<double> sf_pulse_per_arcsec, sf_se_pulse_per_arcsec, sf_temp_c;
  std::optional<double> tc_ppm_per_c, tc_se_ppm_per_c;
  std::optional<double> nonlinearity_max_ppm_fs, asymmetry_ppm, asymmetry_se_ppm;
  std::optional<double> tilt_mrad, tilt_se_mrad;
  std::optional<double> turn_on_repeatability_dph, turn_on_repeatability_lower_dph,
      turn_on_repeatability_upper_dph, max_warmup_s;
  nlohmann::json figures;  ///< the serial's object as acceptance_json and the verdict gave it
};

/// The row of run `run_id` for one serial's object (acceptance_json, judged): its columns taken
/// from the object, computed_utc left empty.
AcceptanceRow acceptance_row(std::int64_t run_id, const nlohmann::json& serial);

/// Replaces every stored row of run `run_id` with `rows` in one transaction (a recomputation, a
/// resumed or replayed run's end: the newest computation is the run's). Throws SqliteError.
void replace_acceptance_rows(Store& store, std::int64_t run_id,
                             const std::vector<AcceptanceRow>& rows);

/// The stored rows of run `run_id`, in the order they were written (the run's slots).
std::vector<AcceptanceRow> acceptance_rows_of_run(Store& store, std::int64_t run_id);
/// The stored rows of `serial`, oldest run first.
std::vector<AcceptanceRow> acceptance_rows_of_serial(Store& store, const std::string& serial);

/// The stored row of `serial` from the newest of `runs` that has one (a fit's runs: the
/// acceptance verdict shown beside its thermal verdict).
std::optional<AcceptanceRow> newest_acceptance_row(Store& store, const std::string& serial,
                                                   const std::vector<std::int64_t>& runs);

/// The run's stored figures as one array of the serials' objects (empty: none stored).
nlohmann::json stored_acceptance_json(Store& store, std::int64_t run_id);

}  // namespace station
