// A fit's coefficients and standard errors as JSON objects keyed by coefficient name
// (B0, k1, k2, k3, k4, k0, kr, kc): the one shape every command and the store use.
#pragma once

#include <nlohmann/json.hpp>

#include "compensation/fit.hpp"

namespace station {

/// {"B0": value, "k1": value, ...}
nlohmann::json coefficients_json(const compensation::FitResult& fit);
/// {"B0": std error, "k1": std error, ...}
nlohmann::json std_errors_json(const compensation::FitResult& fit);
/// {"B0": Newey-West std error, ...}
nlohmann::json std_errors_hac_json(const compensation::FitResult& fit);
/// The fit and its evaluation as every command reports them: coefficients, std_errors,
/// std_errors_hac, hac_lag, bins, r2, residual_rms_dph, condition_number, std_before_dph,
/// std_after_dph, std_ratio, improvement_pct, warnings (the fit's).
nlohmann::json fit_summary_json(const compensation::FitResult& fit,
                                const compensation::Evaluation& eval);

}  // namespace station
