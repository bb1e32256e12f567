// Where a coefficient block's scale-factor model comes from (issue 36): the one place that
// decides which run's rate ladders give it, and when a block says "scale factor: not measured".
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// The scale factor K(T) = K0 (1 + TC 1e-6 (T - t_ref_c)) of one gyro, with what the bias model
/// needs to be put in input units (gyro_tc.h, gyro_tc_rate_dph).
struct ScaleFactorModel {
  double k0_pulse_per_arcsec = 0;     ///< K0 at t_ref_c
  double k0_se_pulse_per_arcsec = 0;  ///< its standard error
  double tc_ppm_per_c = 0;            ///< 0 when one plateau (tc_se_ppm_per_c empty)
  std::optional<double> tc_se_ppm_per_c;
  double t_ref_c = 0;               ///< T_ref of K0, deg C
  double t_min_c = 0, t_max_c = 0;  ///< plateau temperatures the ladders covered, deg C
  std::size_t plateaus = 0;         ///< ladders that gave a scale factor
  std::vector<std::int64_t> runs;   ///< the run whose ladders gave it
  double pulse_weight_arcsec = 0;   ///< w of the bias fit's runs (their slots of the serial)
  double earth_rate_dph = 0;        ///< E along the input axis in the bias fit's runs
};

/// A scale-factor model, or why there is none; `note` says how it was found either way.
struct ScaleFactorSource {
  std::optional<ScaleFactorModel> model;
  std::string note;
};

/// The scale factor for the block of `fit`. Rule: the runs of the fit, newest first, then the
/// serial's other runs, newest first; the first whose acceptance figures (run_acceptance, at the
/// fit's T_ref) hold the serial to a scale factor (held_scale_factor, the rule of its verdict
/// and history) gives it: K0 at T_ref with TC from the fit across the plateaus; or its one
/// ladder's K, TC 0 (noted), K0 at that ladder's temperature. None: "scale factor: not
/// measured" and the block leaves the scale alone. Also none (noted) when the fit's runs differ
/// in the serial's pulse weight or Earth rate, which the bias model needs to be put in input
/// units.
ScaleFactorSource find_scale_factor(Store& store, const FitRecord& fit);

/// "scale factor: K0 0.666668189 +- 4e-06 pulse/arcsec at 25.00 C, TC +2.477 +- 0.16 ppm/C over
/// -39.85..69.85 C; from the rate ladders of run 1 (3 plateaus)" (TC without an error: "TC not
/// measured (0)"), or "scale factor: not measured (…)": one line for people.
std::string scale_factor_text(const ScaleFactorSource& s);

}  // namespace station
