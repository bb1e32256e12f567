// A gyro's scale factor across runs (issue 36, `station history`): each run's stored K and its
// temperature coefficient, and the change from one run to the next against the change their
// standard errors allow. Pure: stored rows in, differences out.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "station/store/acceptance_results.hpp"

namespace station {

/// The change of the scale factor (and of its temperature coefficient, where both runs have
/// one) from one run with a K to the next.
struct ScaleFactorDrift {
  std::int64_t run_id = 0, previous_run_id = 0;
  double delta_ppm = 0;  ///< (K - K_prev) / K_prev * 1e6
  double se_ppm = 0;     ///< sqrt(se^2 + se_prev^2) / K_prev * 1e6: the combined standard error
  std::optional<double> zeta;  ///< delta / se (parts/history.hpp zeta_score); empty: se 0
  std::optional<double> tc_delta_ppm_per_c, tc_se_ppm_per_c, tc_zeta;
  /// K held at temperatures more than 1 C apart (a single ladder's K at its plateau): the
  /// difference carries the temperature coefficient times that gap.
  std::optional<double> temp_gap_c;
  bool drift = false;  ///< |zeta| or |tc_zeta| above kDriftZetaLimit (ISO 13528 action limit)
};

/// Each row with a scale factor against the previous such row (rows oldest run first).
std::vector<ScaleFactorDrift> scale_factor_drift(const std::vector<AcceptanceRow>& rows);

}  // namespace station
