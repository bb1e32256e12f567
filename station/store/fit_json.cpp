// Fit coefficients as JSON objects.
#include "station/store/fit_json.hpp"

#include <fmt/format.h>

#include <cmath>

namespace station {
namespace {

// {name: value}; null for a value the fit does not have (a fit read back from the store has
// no HAC errors: the fits table does not keep them).
nlohmann::json keyed(const compensation::FitResult& fit, const std::vector<double>& values) {
  if (values.size() != fit.names.size()) return nullptr;
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < fit.names.size(); ++i) j[fit.names[i]] = values[i];
  return j;
}

}  // namespace

nlohmann::json coefficients_json(const compensation::FitResult& fit) {
  return keyed(fit, fit.coefficients);
}

nlohmann::json units_json(const compensation::FitResult& fit) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& name : fit.names) j[name] = std::string(compensation::coefficient_unit(name));
  return j;
}

nlohmann::json std_errors_json(const compensation::FitResult& fit) {
  return keyed(fit, fit.std_errors);
}

nlohmann::json std_errors_ols_json(const compensation::FitResult& fit) {
  return keyed(fit, fit.std_errors_ols);
}

nlohmann::json noise_json(const compensation::NoisePrior& n) {
  nlohmann::json j{{"trust_factor", n.trust_factor}};
  if (n.arw_deg_rt_h) j["arw_deg_rt_h"] = *n.arw_deg_rt_h;
  if (n.bias_instability_dph) j["bias_instability_dph"] = *n.bias_instability_dph;
  if (n.rrw_dph_rt_h) j["rrw_dph_rt_h"] = *n.rrw_dph_rt_h;
  return j;
}

compensation::NoisePrior noise_prior_from_json(const nlohmann::json& j) {
  compensation::NoisePrior n;
  const auto opt = [&j](const char* key) {
    return j.contains(key) ? std::optional(j.at(key).get<double>()) : std::nullopt;
  };
  n.arw_deg_rt_h = opt("arw_deg_rt_h");
  n.bias_instability_dph = opt("bias_instability_dph");
  n.rrw_dph_rt_h = opt("rrw_dph_rt_h");
  n.trust_factor = j.value("trust_factor", n.trust_factor);
  return n;
}

nlohmann::json fit_error_model_json(const compensation::FitResult& fit) {
  const compensation::ErrorModel& m = fit.error_model;
  nlohmann::json j{{"method", m.method},
                   {"corr_time_s", m.corr_time_s},
                   {"correlated_share", m.correlated_share},
                   {"sigma_dph", m.sigma_dph},
                   {"rho_per_bin", m.rho_per_bin},
                   {"rrw_dph_per_sqrt_h", m.rrw_dph_per_sqrt_h},
                   {"models_averaged", m.mixture.size()},
                   {"on_search_boundary", m.on_search_boundary}};
  j["prior"] = m.prior ? noise_json(*m.prior) : nlohmann::json();
  const auto& w = m.walk_not_excluded;
  j["walk_not_excluded"] =
      w ? nlohmann::json{{"rrw_dph_per_sqrt_h", w->rrw_dph_per_sqrt_h},
                         {"at_search_edge", m.walk_bound_at_search_edge},
                         {"std_errors", keyed(fit, fit.std_errors_walk_not_excluded)}}
        : nlohmann::json();
  j["walk_assessed"] = m.walk_assessed;
  return j;
}

void read_walk_not_excluded(const nlohmann::json& j, compensation::FitResult& fit) {
  // Fits stored before issue 32 carry neither: their walk was searched but not reported.
  fit.error_model.walk_assessed = j.value("walk_assessed", true);
  if (!j.contains("walk_not_excluded") || j.at("walk_not_excluded").is_null()) return;
  const auto& w = j.at("walk_not_excluded");
  compensation::ErrorModel::Component c;
  c.rrw_dph_per_sqrt_h = w.at("rrw_dph_per_sqrt_h").get<double>();
  fit.error_model.walk_not_excluded = c;
  fit.error_model.walk_bound_at_search_edge = w.value("at_search_edge", false);
  if (!w.at("std_errors").is_object()) return;
  for (const auto& n : fit.names)
    fit.std_errors_walk_not_excluded.push_back(w.at("std_errors").at(n));
}

std::string walk_text(const compensation::FitResult& fit) {
  const auto& m = fit.error_model;
  if (m.prior) {
    const auto& p = *m.prior;
    const auto term = [](const char* name, const std::optional<double>& v, const char* unit) {
      return v ? fmt::format(" {} {:.3g} {}", name, *v, unit) : std::string();
    };
    return fmt::format("noise: the part's{}{}{} (trust x{:g}) {}",
                       term("N", p.arw_deg_rt_h, "deg/sqrt(h)"),
                       term("B", p.bias_instability_dph, "deg/h"),
                       term("K", p.rrw_dph_rt_h, "deg/h/sqrt(h)"), p.trust_factor,
                       m.walk_assessed ? "weighs the error model"
                                       : "weighed nothing: too few bins for an error model");
  }
  if (!m.walk_assessed) return "walk: not assessed (too few bins for an error model, or none fits)";
  if (!m.walk_not_excluded) return "walk: the bins exclude a rate random walk (95 %)";
  std::string k1;
  for (std::size_t i = 0; i < fit.names.size() && i < fit.std_errors_walk_not_excluded.size(); ++i)
    if (fit.names[i] == "k1")
      k1 = fmt::format("; under it k1 +- {:.2e} deg/h/C (reported +- {:.2e})",
                       fit.std_errors_walk_not_excluded[i], fit.std_errors[i]);
  return fmt::format(
      "walk: the bins cannot exclude a rate random walk up to {}K = {:.2e} deg/h/sqrt(h) (95 "
      "%{}){}; "
      "no part noise given (a part file's [part.\"PN\".noise] decides it)",
      m.walk_bound_at_search_edge ? "at least " : "", m.walk_not_excluded->rrw_dph_per_sqrt_h,
      m.walk_bound_at_search_edge ? ", the search's largest walk" : "", k1);
}

std::string error_model_text(const compensation::ErrorModel& m) {
  const std::string averaged =
      m.mixture.size() > 1
          ? fmt::format("; SE averaged over {} error models the bins cannot tell apart",
                        m.mixture.size())
          : std::string();
  if (m.correlated_share <= 0 && m.rrw_dph_per_sqrt_h <= 0) {
    return fmt::format("errors: {} (s = {:.2e} deg/h per bin){}",
                       m.method == "iid" ? "independent bins, no correlated noise found" : m.method,
                       m.sigma_dph, averaged);
  }
  return fmt::format(
      "errors (REML, most likely): white + Gauss-Markov s = {:.2e} deg/h per bin, {:.0f} % "
      "correlated with tau {:.0f} s (neighbouring bins {:.2f}), rate random walk {:.2e} "
      "deg/h/sqrt(h){}",
      m.sigma_dph, 100.0 * m.correlated_share, m.corr_time_s, m.rho_per_bin, m.rrw_dph_per_sqrt_h,
      averaged);
}

compensation::ErrorModel error_model_from_json(const nlohmann::json& j) {
  compensation::ErrorModel m;
  m.method = j.value("method", m.method);
  m.corr_time_s = j.value("corr_time_s", 0.0);
  m.correlated_share = j.value("correlated_share", 0.0);
  m.sigma_dph = j.value("sigma_dph", 0.0);
  m.rho_per_bin = j.value("rho_per_bin", 0.0);
  m.rrw_dph_per_sqrt_h = j.value("rrw_dph_per_sqrt_h", 0.0);
  m.on_search_boundary = j.value("on_search_boundary", false);
  if (j.contains("prior") && j.at("prior").is_object())
    m.prior = noise_prior_from_json(j.at("prior"));
  return m;
}

nlohmann::json std_errors_hac_json(const compensation::FitResult& fit) {
  return keyed(fit, fit.std_errors_hac);
}

nlohmann::json fit_summary_json(const compensation::FitResult& fit,
                                const compensation::Evaluation& eval) {
  return {{"coefficients", coefficients_json(fit)},
          {"units", units_json(fit)},
          {"std_errors", std_errors_json(fit)},
          {"std_errors_ols", std_errors_ols_json(fit)},
          {"error_model", fit_error_model_json(fit)},
          {"walk", walk_text(fit)},
          {"std_errors_hac", std_errors_hac_json(fit)},
          {"hac_lag", fit.hac_lag},
          {"bins", fit.n_points},
          {"r2", fit.r2},
          {"residual_rms_dph", fit.residual_rms_dph},
          {"condition_number", fit.condition_number},
          {"std_before_dph", eval.std_before_dph},
          {"std_after_dph", eval.std_after_dph},
          {"std_ratio", std_ratio_json(eval)},
          {"improvement_pct",
           eval.improvement_pct ? nlohmann::json(*eval.improvement_pct) : nlohmann::json(nullptr)},
          {"warnings", fit.warnings}};
}

nlohmann::json fit_summary_json_with_diagnostics(const compensation::FitResult& fit,
                                                 const compensation::Evaluation& eval) {
  nlohmann::json j = fit_summary_json(fit, eval);
  j["diagnostics"] = diagnostics_json(fit);
  return j;
}

nlohmann::json diagnostics_json(const compensation::FitResult& fit) {
  nlohmann::json vif = nlohmann::json::object(), cands = nlohmann::json::array();
  for (std::size_t j = 0; j < fit.vif.size() && j + 1 < fit.names.size(); ++j)
    vif[fit.names[j + 1]] = std::isfinite(fit.vif[j]) ? nlohmann::json(fit.vif[j]) : nullptr;
  for (const auto& c : fit.candidates) {
    nlohmann::json coef = nlohmann::json::object();
    for (std::size_t i = 0; i < c.coefficients.size(); ++i)
      coef[i < fit.names.size() ? fit.names[i] : c.option] = c.coefficients[i];
    cands.push_back({{"term", c.option},
                     {"value", c.value},
                     {"std_error", c.std_error},
                     {"likelihood_ratio", c.likelihood_ratio},
                     {"z", c.z},
                     {"significant", c.significant},
                     {"coefficients_with_it", coef}});
  }
  return {{"vif", vif},
          {"vif_limit", 10.0},
          {"missing_term_candidates", cands},
          {"z_critical", fit.candidate_z_critical}};
}

nlohmann::json std_ratio_json(const compensation::Evaluation& eval) {
  return eval.std_ratio ? nlohmann::json(*eval.std_ratio) : nlohmann::json(nullptr);
}

std::string std_ratio_text(const compensation::Evaluation& eval) {
  return eval.std_ratio ? fmt::format("{:.3f}", *eval.std_ratio) : "undefined";
}

std::string evaluation_text(const compensation::Evaluation& eval) {
  const auto stds = fmt::format("std before {:.5f} deg/h, after {:.5f} deg/h", eval.std_before_dph,
                                eval.std_after_dph);
  if (!eval.std_ratio || !eval.improvement_pct) {
    return stds + ", ratio undefined (the std before is at rounding level: nothing to compensate)";
  }
  return fmt::format("{}, ratio {:.3f} ({:.1f} % better)", stds, *eval.std_ratio,
                     *eval.improvement_pct);
}

}  // namespace station
