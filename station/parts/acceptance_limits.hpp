// A part's limits for the acceptance steps' figures (issue 36): [part."PN".acceptance] of the part
// file, limits as data (OpenHTF's idea), each optional.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "station/parts/limit_range.hpp"

namespace station {

struct AcceptanceLimits {
  /// K at 25 C (the ladders' temperature model), or the one ladder's K, pulse/arcsec.
  LimitRange sf_pulse_per_arcsec;
  LimitRange sf_tc_ppm_per_c;                    ///< the scale factor's temperature coefficient
  std::optional<double> max_nonlinearity_ppm_fs;  ///< largest residual of every ladder
  std::optional<double> max_asymmetry_ppm;        ///< |asymmetry| of every ladder
  std::optional<double> max_tilt_mrad;            ///< input-axis tilt of every positions step
  std::optional<double> max_turn_on_repeatability_dph;  ///< turn-on-to-turn-on sigma
  std::optional<double> max_warmup_s;                   ///< the longest turn-on's warm-up
};

/// Reads `[acceptance]` of a part's table (empty when absent); throws InputError naming the key.
std::optional<AcceptanceLimits> read_acceptance_limits(const TomlView& part);
/// As stored with a part's limits, and back (throws nlohmann::json::exception on a bad object).
nlohmann::json acceptance_limits_json(const AcceptanceLimits& a);
AcceptanceLimits acceptance_limits_from_json(const nlohmann::json& j);

}  // namespace station
