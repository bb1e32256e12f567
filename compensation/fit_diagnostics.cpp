#include "compensation/fit_diagnostics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "compensation/model_choice.hpp"

namespace station::compensation {
namespace {

/// Phi^-1(1 - 0.005 / m), m = 1..4: the two-sided 1 % Bonferroni bound for m tests (standard
/// normal quantiles 0.995, 0.9975, 0.99833, 0.99875; Abramowitz & Stegun, Table 26.5).
constexpr std::array<double, 4> kZCritical{2.5758, 2.8070, 2.9352, 3.0233};

std::string num(double v, const char* fmt = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

bool has_data(Term t, const ModelInput& in) {
  if (t == Term::dTdt) return in.dtdt_c_per_h.size() == in.bias_dph.size();
  if (t == Term::gradTdT) return in.grad_c.size() == in.bias_dph.size();
  return true;
}

/// The value of coefficient `name` in a fit, or NaN.
double value_of(const FitResult& f, const std::string& name) {
  for (std::size_t i = 0; i < f.names.size(); ++i)
    if (f.names[i] == name) return f.coefficients[i];
  return NAN;
}

void warn_missing(FitResult& fit, const FitResult::Candidate& c, const FitResult& extended) {
  std::string with;
  for (const char* k : {"k1", "k0"}) {
    const double now = value_of(fit, k), then = value_of(extended, k);
    if (std::isfinite(now))
      with += std::string(with.empty() ? "" : ", ") + k + " " + num(now, "%.4g") + " -> " +
              num(then, "%.4g");
  }
  fit.warnings.push_back("the model may be missing term " + c.option +
                         ": adding it explains "
                         "significantly more (likelihood ratio " +
                         num(c.likelihood_ratio, "%.1f") + ", z = " + num(c.z, "%.1f") +
                         ", beyond " + num(fit.candidate_z_critical, "%.2f") +
                         ", each model with its own error model, 1 % over the candidates); with "
                         "it " +
                         with + " (fit --terms " + c.option + " ... to include it)");
}

/// 1 / (1 - r^2) of dT against gradT: the VIF k1 and k0 would have alone together.
double pair_vif(const ModelInput& in) {
  const std::size_t n = std::min(in.temp_c.size(), in.grad_c.size());
  if (n < 3) return 1.0;
  double mt = 0, mg = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mt += in.temp_c[i] / static_cast<double>(n);
    mg += in.grad_c[i] / static_cast<double>(n);
  }
  double stt = 0, sgg = 0, stg = 0;
  for (std::size_t i = 0; i < n; ++i) {
    stt += (in.temp_c[i] - mt) * (in.temp_c[i] - mt);
    sgg += (in.grad_c[i] - mg) * (in.grad_c[i] - mg);
    stg += (in.temp_c[i] - mt) * (in.grad_c[i] - mg);
  }
  if (!(stt > 0 && sgg > 0)) return INFINITY;
  const double r2 = stg * stg / (stt * sgg);
  return r2 < 1 ? 1.0 / (1.0 - r2) : INFINITY;
}

void warn_collinear(const ModelInput& in, FitResult& fit) {
  bool has_k1 = false, has_k0 = false;
  for (std::size_t j = 0; j < fit.vif.size() && j + 1 < fit.names.size(); ++j) {
    const std::string& name = fit.names[j + 1];
    has_k1 = has_k1 || name == "k1";
    has_k0 = has_k0 || name == "k0";
    if (fit.vif[j] > kVifLimit)
      fit.warnings.push_back("term " + name + " is poorly determined: variance inflation " +
                             num(fit.vif[j], "%.0f") +
                             " > 10 (it is nearly a combination of "
                             "the other terms)");
  }
  if (!(has_k1 && has_k0)) return;
  const double vif = pair_vif(in);
  if (vif > kVifLimit)
    fit.warnings.push_back(
        "k1 and k0 cannot be separated on these runs: the gradient follows the temperature "
        "(dT against gradT alone: variance inflation " +
        num(vif, "%.0f") +
        " > 10); fit runs at two heating rates together (ramp_10 with ramp_20: station fit "
        "--serial SN --runs A,B), where the gradient differs at the same temperature");
}

}  // namespace

std::vector<Term> candidates_for(const ModelInput& in, const ModelSpec& spec) {
  std::vector<Term> tried;
  for (const Term t : {Term::dT2, Term::dT3, Term::dTdt, Term::gradTdT})
    if (std::find(spec.terms.begin(), spec.terms.end(), t) == spec.terms.end() && has_data(t, in))
      tried.push_back(t);
  return tried;
}

double candidate_z_critical(std::size_t candidates) {
  return candidates == 0 ? 0.0 : kZCritical[std::min<std::size_t>(candidates, 4) - 1];
}

void diagnose_fit(const ModelInput& in, FitResult& fit, model_search::Problem& lack_of_fit) {
  warn_collinear(in, fit);
  const std::vector<Term> tried = candidates_for(in, fit.spec);
  if (tried.empty()) return;
  fit.candidate_z_critical = candidate_z_critical(tried.size());
  const std::vector<double> lr =
      extension_likelihood_ratios(lack_of_fit, fit.candidate_z_critical * fit.candidate_z_critical);
  std::optional<std::size_t> best;  // index into fit.candidates
  FitResult best_fit;
  for (std::size_t k = 0; k < tried.size(); ++k) {
    ModelSpec spec = fit.spec;
    spec.terms.push_back(tried[k]);
    FitResult e;
    try {
      e = fit_model_under(in, spec, fit.error_model);
    } catch (const std::exception&) {
      continue;  // too few bins, or the candidate is collinear with the model: nothing to say
    }
    FitResult::Candidate c;
    c.option = std::string(term_option_name(tried[k]));
    c.value = e.coefficients.back();
    c.std_error = e.std_errors.back();
    c.likelihood_ratio = std::max(lr[k], 0.0);
    c.z = std::copysign(std::sqrt(c.likelihood_ratio), c.value);
    c.significant = std::abs(c.z) > fit.candidate_z_critical;
    c.coefficients = e.coefficients;
    fit.candidates.push_back(c);
    if (c.significant && (!best || std::abs(c.z) > std::abs(fit.candidates[*best].z))) {
      best = fit.candidates.size() - 1;
      best_fit = std::move(e);
    }
  }
  if (best) warn_missing(fit, fit.candidates[*best], best_fit);
}

}  // namespace station::compensation
