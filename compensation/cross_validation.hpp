// Leave-one-run-out cross-validation of the thermal model: fit on every run but one, predict the
// one left out, repeat for each run. The prediction error on runs a fit did not see, beside the
// in-sample residual, shows an over-fitted model (too many terms fit noise: the in-sample std
// falls while the held-out error rises). Hastie, Tibshirani & Friedman, The Elements of
// Statistical Learning, 2nd ed., §7.10 (K-fold cross-validation, here with a fold per run so
// that correlated bins of one run never sit on both sides).
#pragma once

#include <cstddef>
#include <vector>

#include "compensation/fit.hpp"

namespace station::compensation {

/// One held-out run.
struct HeldOutRun {
  int segment = 0;       ///< the run's segment index in the input
  std::size_t bins = 0;  ///< its bins
  double rms_dph = 0;    ///< RMS of bias - prediction over its bins, deg/h
  double std_dph = 0;    ///< sample std of bias - prediction (the compensated std), deg/h
};

/// The cross-validation of one model over several runs.
struct CrossValidation {
  std::vector<HeldOutRun> runs;
  double pooled_rms_dph = 0;     ///< RMS of the prediction error over every held-out bin
  double in_sample_rms_dph = 0;  ///< residual RMS of the fit to every run
};

/// Leave-one-segment-out over `in.segment` (the run index per bin). Throws std::invalid_argument
/// for fewer than two segments, and DataError when a fit without one run is impossible.
CrossValidation leave_one_run_out(const ModelInput& in, const ModelSpec& spec);

}  // namespace station::compensation
