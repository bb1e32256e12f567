// A gyro's scale factor across runs.
#include "station/acceptance/acceptance_history.hpp"

#include <cmath>

#include "station/parts/history.hpp"

namespace station {
namespace {

ScaleFactorDrift drift_of(const AcceptanceRow& now, const AcceptanceRow& prev) {
  ScaleFactorDrift d;
  d.run_id = now.run_id;
  d.previous_run_id = prev.run_id;
  const double k = *now.sf_pulse_per_arcsec, k_prev = *prev.sf_pulse_per_arcsec;
  const double se = now.sf_se_pulse_per_arcsec.value_or(0.0);
  const double se_prev = prev.sf_se_pulse_per_arcsec.value_or(0.0);
  d.delta_ppm = (k - k_prev) / k_prev * 1e6;
  d.se_ppm = std::sqrt(se * se + se_prev * se_prev) / std::abs(k_prev) * 1e6;
  d.zeta = zeta_score(k, se, k_prev, se_prev);
  if (now.sf_temp_c && prev.sf_temp_c &&
      std::abs(*now.sf_temp_c - *prev.sf_temp_c) > kHeldTempToleranceC)
    d.temp_gap_c = *now.sf_temp_c - *prev.sf_temp_c;
  if (now.tc_ppm_per_c && prev.tc_ppm_per_c) {
    const double u = now.tc_se_ppm_per_c.value_or(0.0), u_prev = prev.tc_se_ppm_per_c.value_or(0.0);
    d.tc_delta_ppm_per_c = *now.tc_ppm_per_c - *prev.tc_ppm_per_c;
    d.tc_se_ppm_per_c = std::sqrt(u * u + u_prev * u_prev);
    d.tc_zeta = zeta_score(*now.tc_ppm_per_c, u, *prev.tc_ppm_per_c, u_prev);
  }
  d.drift = (d.zeta && std::abs(*d.zeta) > kDriftZetaLimit) ||
            (d.tc_zeta && std::abs(*d.tc_zeta) > kDriftZetaLimit);
  return d;
}

}  // namespace

std::vector<ScaleFactorDrift> scale_factor_drift(const std::vector<AcceptanceRow>& rows) {
  std::vector<ScaleFactorDrift> out;
  const AcceptanceRow* prev = nullptr;
  for (const auto& r : rows) {
    if (!r.sf_pulse_per_arcsec || !(*r.sf_pulse_per_arcsec != 0)) continue;
    if (prev != nullptr) out.push_back(drift_of(r, *prev));
    prev = &r;
  }
  return out;
}

}  // namespace station
