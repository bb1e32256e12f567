// A fit's model as people read it, and what a run's report shows of fits and releases that came
// after the run: the report is a record of its run (issue 35), so later fits are dated notes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "compensation/fit.hpp"
#include "station/release/releases.hpp"
#include "station/store/store.hpp"

namespace station::report {

/// The model a fit was made with, built from its coefficient names (Zhou et al. 2013, eq. (4),
/// extended by the terms of compensation/fit.hpp): "B = B0 + k1·ΔT + k0·∇T" for the paper's
/// model, "B = B0 + k1·ΔT + k2·ΔT² + k3·ΔT³" for a cubic one. Plain text (UTF-8), not HTML.
std::string model_formula(const compensation::FitResult& fit);

/// A fit other than the one the report shows, with its newest release (if any).
struct OtherFit {
  FitRecord fit;
  std::optional<ReleaseRow> release;
};

}  // namespace station::report
