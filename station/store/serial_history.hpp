// Reads across runs and fits by serial number: what `station history` and `fit --all` list.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// A fit's coefficients or standard errors JSON ({"B0": x, "k1": y, ...}) as (name, value) pairs;
/// entries that are not numbers are left out.
std::vector<std::pair<std::string, double>> values_by_name(const std::string& json_text);

/// Every serial any run recorded, sorted.
std::vector<std::string> all_serials(Store& store);

/// A run as one serial's history shows it.
struct SerialRun {
  std::int64_t run_id = 0;
  std::string started_utc, ended_utc, state, protocol_name, station, operator_name;
  int slot = 0;
  std::optional<std::string> part_number;
};
/// Every run that recorded `serial`, oldest first.
std::vector<SerialRun> serial_runs(Store& store, const std::string& serial);

/// A fit as one serial's history shows it: coefficients and standard errors by name.
struct SerialFitRow {
  std::int64_t fit_id = 0;
  std::string created_utc, terms;
  std::vector<std::int64_t> runs;
  std::vector<std::pair<std::string, double>> coefficients, std_errors;
  std::int64_t n_bins = 0;
  std::optional<double> std_ratio;
  double std_after_dph = 0;
  std::optional<std::string> part_number, verdict_json;
  std::string station;  ///< the station that made it (fleet history); empty for a local read
  /// Value of coefficient `name` (empty when the fit has no such term).
  std::optional<double> coefficient(const std::string& name) const;
  /// Its standard error (empty when the fit has no such term).
  std::optional<double> std_error(const std::string& name) const;
};
/// Every fit of `serial`, oldest first.
std::vector<SerialFitRow> serial_fits(Store& store, const std::string& serial);

}  // namespace station
