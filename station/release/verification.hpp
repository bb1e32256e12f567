// Verification on an independent run (ArduPilot's tempcal_IMU.py --log-parm, done by the
// station): a fit's coefficient block, applied as the navigation computer applies it
// (gyro_tc_correct, with its clamping), to the bins and the 1 Hz record of a run the fit did not
// use. Stored (migration 6) with its verdict against the part's verification limits.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "compensation/fit.hpp"
#include "station/parts/part_file.hpp"
#include "station/parts/verdict.hpp"
#include "station/store/store.hpp"

namespace station {

/// Fewer complete bins than this on the verification run: the figures are shown, but no
/// verification limit can be shown to hold (they fail): a std over a handful of bins says
/// nothing (one bin has a std of 0).
inline constexpr std::size_t kMinVerifyBins = 6;

/// What a verification shows.
struct VerificationResult {
  std::int64_t id = 0;  ///< verifications.id (0 before it is stored)
  std::string serial, created_utc;
  std::int64_t fit_id = 0, run_id = 0;
  std::size_t bins = 0;           ///< complete bins of the run
  compensation::Evaluation eval;  ///< std before / after over those bins, ratio
  double mean_residual_dph = 0;   ///< mean compensated bias
  /// Slope of the compensated bias against T (what the model left, deg/h/C) and its honest
  /// standard error (fit_model, terms dT); empty when too few bins to fit a line.
  std::optional<double> drift_dph_per_c, drift_se_dph_per_c;
  std::optional<double> adev_floor_dph;  ///< ADEV floor of the compensated 1 Hz record
  std::size_t clamped_bins = 0;          ///< bins with T or gradT outside the fit's span
  std::optional<std::string> part_number;
  std::optional<Verdict> verdict;     ///< against max_verify_std_dph / max_verify_ratio
  std::vector<std::string> warnings;  ///< too few bins, a run that did not complete
  /// Per bin, for the report's figure: mid time (s), T (C), bias before and after (deg/h).
  std::vector<double> t_s, temp_c, before_dph, after_dph;
};

/// Applies fit `fit` to run `run_id` and judges it against `limits` (verification limits only).
/// Throws InputError when the run was among the fit's runs, did not record the serial, or has
/// no complete bin; ReleaseRefused when the fit cannot travel in a block.
VerificationResult verify_fit(Store& store, const FitRecord& fit, std::int64_t run_id,
                              const std::optional<PartLimits>& limits);

/// Stores a verification (and an event 'verification' on its run); returns its id.
std::int64_t save_verification(Store& store, VerificationResult& v);

/// The stored verification that verifying fit `fit_id` on run `run_id` against `limits` again
/// would repeat: the newest of that fit on that run with the same part number (none: no part)
/// whose stored verdict is the one `limits` give its stored figures today (a part file edited
/// since gives another, so it is not the same verification). Empty when there is none. The
/// figures are a function of the stored fit and the run's stored bins, which do not change.
std::optional<VerificationResult> stored_verification(Store& store, std::int64_t fit_id,
                                                      std::int64_t run_id,
                                                      const std::optional<PartLimits>& limits);

/// The stored verifications of a run, oldest first (figures without the per-bin series: the
/// report recomputes them with verify_fit from the stored fit).
std::vector<VerificationResult> verifications_of_run(Store& store, std::int64_t run_id);

/// {"serial","fit_id","run_id","std_before_dph","std_after_dph","ratio","mean_residual_dph",
///  "verdict", ...}: the --json output and the stored result_json (without the series).
nlohmann::json verification_json(const VerificationResult& v);

}  // namespace station
