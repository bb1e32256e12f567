// A run's acceptance figures as stored (migration 12, issue 36): one row per (run, serial), the
// figures compared across runs as columns and the serial's whole object (acceptance_json with its
// verdict) as JSON; every power_cycles step's turn-on figures in a row of their own (migration 15).
// Computed and written by station/acceptance/acceptance_record.hpp; read by the API, `history`,
// `fit` and the end summary.
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

/// One power_cycles step's turn-on figures of one serial (migration 15): the step's object of the
/// serial's turn_on_steps, or its one turn_on object as step 1.
struct TurnOnStepRow {
  int step_no = 0;                ///< its place among the run's power_cycles steps, 1..n
  std::optional<int> step_index;  ///< in the protocol, 0-based; empty for a run's only step
  std::optional<std::string> label;
  std::optional<double> temp_c;      ///< sensor A's mean over the powered windows, C
  bool ok = false;                   ///< computed
  std::optional<std::string> error;  ///< why not computed
  std::optional<int> turn_ons;
  std::optional<double> repeatability_dph, repeatability_lower_dph, repeatability_upper_dph,
      max_warmup_s;
  bool operator==(const TurnOnStepRow&) const = default;
};

/// Every power_cycles step of one serial's object (acceptance_json), in the protocol's order.
std::vector<TurnOnStepRow> turn_on_step_rows(const nlohmann::json& serial);

/// "'hot' (step 9, 70.0 C)", "step 2", or "" for a run's only step: a step's name in text.
std::string turn_on_step_name(const TurnOnStepRow& s);

/// "sigma 0.0041 deg/h (interval 0.0021 to 0.025), longest warm-up 120 s", or "not computed: why":
/// a step's figures in text (`history`, `station fleet`).
std::string turn_on_step_text(const TurnOnStepRow& s);

/// The steps as JSON (`history --json`, `station fleet --json`): an object per step with the
/// struct's fields under their names, null where empty.
nlohmann::json turn_on_steps_json(const std::vector<TurnOnStepRow>& steps);

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
      turn_on_repeatability_upper_dph, max_warmup_s;  ///< the first power_cycles step's
  std::vector<TurnOnStepRow> turn_on_steps;           ///< every power_cycles step's
  nlohmann::json figures;  ///< the serial's object as acceptance_json and the verdict gave it
};

/// The row of run `run_id` for one serial's object (acceptance_json, judged): its columns and its
/// turn-on steps taken from the object, computed_utc left empty.
AcceptanceRow acceptance_row(std::int64_t run_id, const nlohmann::json& serial);

/// Replaces every stored row of run `run_id` (and its turn-on steps) with `rows` in one transaction
/// (a recomputation, a resumed or replayed run's end: the newest computation is the run's). Throws
/// SqliteError.
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
