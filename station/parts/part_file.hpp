// The part file (TOML, schemas/parts.schema.json): acceptance limits per part number. Read and
// checked completely, together with the station configuration's slots, before anything moves;
// every error is one line naming the file, the line and the key.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "compensation/noise_prior.hpp"
#include "station/config/config.hpp"
#include "station/parts/acceptance_limits.hpp"
#include "station/parts/limit_range.hpp"

namespace station {

/// What a gyro of one part number must show to pass. Every limit is optional: an absent one is
/// not checked.
struct PartLimits {
  std::string number;                          ///< the part number
  std::string description;                     ///< free text
  LimitRange b0_dph;                           ///< B0, deg/h
  LimitRange k1_dph_per_c;                     ///< k1, deg/h/C
  LimitRange k0_dph_per_c;                     ///< k0 (gradient), deg/h/C
  std::optional<double> max_std_after_dph;     ///< std of the compensated bins, deg/h
  std::optional<double> max_std_ratio;         ///< std after / std before
  std::optional<double> max_adev_floor_dph;    ///< ADEV floor of the compensated 1 Hz record
  std::optional<long long> min_complete_bins;  ///< complete bins the fit used
  std::optional<double> max_k1_se_dph_per_c;   ///< standard error of k1, deg/h/C
  std::optional<double> max_k0_se_dph_per_c;   ///< standard error of k0, deg/h/C
  /// Verification on an independent run (`station verify`), not part of a fit's verdict:
  std::optional<double> max_verify_std_dph;  ///< std of the compensated bins, deg/h
  std::optional<double> max_verify_ratio;    ///< std after / std before on that run
  /// The model production fits ("dT,gradT", compensation::parse_terms): a part file may fix it.
  std::optional<std::string> model;
  /// The part's noise ([part."PN".noise]): a prior on the fit's error model
  /// (compensation/noise_prior.hpp), from the data sheet or `station adev`'s term fit.
  std::optional<compensation::NoisePrior> noise;
  /// Limits of the acceptance steps' figures ([part."PN".acceptance], issue 36).
  std::optional<AcceptanceLimits> acceptance;
};

/// A whole part file.
struct PartFile {
  std::string path;
  std::map<std::string, PartLimits> parts;  ///< by part number
};

/// Parses part-file text labelled as `path`; throws InputError ("FILE:LINE: key 'k': ...").
PartFile parse_part_file(const std::string& text, const std::string& path);
/// Reads and parses a part file; a missing or unreadable file is an InputError naming it.
PartFile load_part_file(const std::string& path);

/// The limits each slot's gyro is judged against, by serial: from the part file at
/// `parts_path` (the --parts option; empty: the configuration's [station] parts). Slots without
/// a part number get none. Throws InputError for a bad part file, a slot naming a part the file
/// lacks, or slots naming parts with no part file given.
std::map<std::string, PartLimits> slot_part_limits(const StationConfig& config,
                                                   const std::string& parts_path);

/// The limits as stored with a run (run_slots.part_limits_json): the part-file keys.
nlohmann::json part_limits_json(const PartLimits& limits);
/// The inverse of part_limits_json; throws std::invalid_argument on a malformed object.
PartLimits part_limits_from_json(const nlohmann::json& j);

}  // namespace station
