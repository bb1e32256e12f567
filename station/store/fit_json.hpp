// A fit's coefficients and standard errors as JSON objects keyed by coefficient name
// (B0, k1, k2, k3, k4, k0, kr, kc), and its evaluation for people: the one shape every command
// and the store use.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "compensation/fit.hpp"

namespace station {

/// {"B0": value, "k1": value, ...}
nlohmann::json coefficients_json(const compensation::FitResult& fit);
/// {"B0": std error, "k1": std error, ...}
/// {name: unit} of each coefficient ("B0": "deg/h", "k1": "deg/h/C", ...): the `units`
/// object beside every JSON `coefficients`.
nlohmann::json units_json(const compensation::FitResult& fit);
nlohmann::json std_errors_json(const compensation::FitResult& fit);
/// {"B0": Newey-West std error, ...}
/// {name: OLS standard error} (iid bins; kept for comparison).
nlohmann::json std_errors_ols_json(const compensation::FitResult& fit);
/// One line for people: "errors: white + Gauss-Markov noise, tau 3400 s, 21 % of the variance,
/// neighbouring bins correlated 0.84 (REML)" or "errors: independent bins (OLS)".
std::string error_model_text(const compensation::ErrorModel& model);
/// Reads fit_error_model_json back; missing keys stay at their defaults.
compensation::ErrorModel error_model_from_json(const nlohmann::json& j);
/// {"arw_deg_rt_h", "bias_instability_dph", "rrw_dph_rt_h", "trust_factor"} (absent: not given).
nlohmann::json noise_json(const compensation::NoisePrior& noise);
/// The inverse of noise_json; throws nlohmann::json::exception on a malformed object.
compensation::NoisePrior noise_prior_from_json(const nlohmann::json& j);
/// The error model behind std_errors, what the store keeps: {"method", "corr_time_s",
/// "correlated_share", "sigma_dph", "rho_per_bin", "rrw_dph_per_sqrt_h", "models_averaged",
/// "on_search_boundary", "prior", "walk_not_excluded": {"rrw_dph_per_sqrt_h", "at_search_edge",
/// "std_errors"} (null with a prior, or when the bins exclude every walk), "walk_assessed"}.
nlohmann::json fit_error_model_json(const compensation::FitResult& fit);
/// Reads fit_error_model_json's walk back into `fit` (its names set).
void read_walk_not_excluded(const nlohmann::json& j, compensation::FitResult& fit);
/// One line on the walk: with the part's noise given, what was given; without, the largest walk
/// the bins cannot exclude and k1's error under it (issue 32).
std::string walk_text(const compensation::FitResult& fit);
nlohmann::json std_errors_hac_json(const compensation::FitResult& fit);
/// The fit and its evaluation as every command reports them: coefficients, std_errors,
/// std_errors_hac, hac_lag, bins, r2, residual_rms_dph, condition_number, std_before_dph,
/// std_after_dph, std_ratio, improvement_pct (both null when the ratio is undefined), warnings
/// (the fit's). The shape of a stored fit (sessions' result.json compare it).
nlohmann::json fit_summary_json(const compensation::FitResult& fit,
                                const compensation::Evaluation& eval);
/// fit_summary_json plus "diagnostics" (diagnostics_json): a fit just computed (analyze, fit);
/// a fit read back from the store has no diagnostics (only their warnings are stored).
nlohmann::json fit_summary_json_with_diagnostics(const compensation::FitResult& fit,
                                                 const compensation::Evaluation& eval);
/// {"vif": {name: VIF}, "vif_limit", "missing_term_candidates": [{"term", "value", "std_error",
/// "likelihood_ratio", "z", "significant", "coefficients_with_it"}], "z_critical"}
/// (compensation/fit_diagnostics.hpp: z is the likelihood ratio's signed root, std_error the
/// Wald error under the fit's own error model).
nlohmann::json diagnostics_json(const compensation::FitResult& fit);
/// The std ratio as JSON: a number, or null when undefined.
nlohmann::json std_ratio_json(const compensation::Evaluation& eval);
/// The std ratio for people: "0.384", or "undefined".
std::string std_ratio_text(const compensation::Evaluation& eval);
/// "std before 0.01234 deg/h, after 0.00160 deg/h, ratio 0.130 (87.0 % better)"; an undefined
/// ratio reads "ratio undefined (the std before is at rounding level: nothing to compensate)".
std::string evaluation_text(const compensation::Evaluation& eval);

}  // namespace station
