// Calibration history: scatter (sample std, RMS SE, Birge ratio) and ζ-score drift flags.
#include "station/parts/history.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace station {
namespace {

// The calibrations: per distinct run set and terms the newest fit, ordered by the newest run
// they used.
std::vector<Calibration> calibrations_of(const std::vector<SerialFitRow>& fits) {
  std::map<std::pair<std::vector<std::int64_t>, std::string>, const SerialFitRow*> by_runs;
  for (const auto& f : fits) by_runs[{f.runs, f.terms}] = &f;  // oldest first: the newest wins
  std::vector<Calibration> out;
  for (const auto& [runs, f] : by_runs) out.push_back({f});
  const auto newest_run = [](const Calibration& c) {
    return c.fit->runs.empty() ? 0 : *std::max_element(c.fit->runs.begin(), c.fit->runs.end());
  };
  std::sort(out.begin(), out.end(), [&](const Calibration& a, const Calibration& b) {
    return std::pair(newest_run(a), a.fit->fit_id) < std::pair(newest_run(b), b.fit->fit_id);
  });
  return out;
}

// Birge ratio: R_B = sqrt(chi2 / (n - 1)) about the inverse-variance weighted mean (R. T. Birge,
// Phys. Rev. 40 (1932) 207; Kacker, Datla, Parr, Metrologia 39 (2002) 279).
CoefficientScatter scatter_of(const std::vector<Calibration>& cals, const std::string& terms,
                              const std::string& name) {
  std::vector<double> k, se;
  for (const auto& c : cals) {
    const auto v = c.fit->coefficient(name), u = c.fit->std_error(name);
    if (c.fit->terms != terms || !v || !u) continue;
    k.push_back(*v);
    se.push_back(*u);
  }
  CoefficientScatter s;
  s.coefficient = name;
  s.n = static_cast<int>(k.size());
  if (k.empty()) return s;
  const auto n = static_cast<double>(k.size());
  double sum = 0, ss_se = 0, w_sum = 0, wk_sum = 0;
  for (std::size_t i = 0; i < k.size(); ++i) {
    sum += k[i];
    ss_se += se[i] * se[i];
    if (se[i] > 0) {
      w_sum += 1 / (se[i] * se[i]);
      wk_sum += k[i] / (se[i] * se[i]);
    }
  }
  s.mean = sum / n;
  s.rms_se = std::sqrt(ss_se / n);
  if (k.size() < 2) return s;
  double ss = 0;
  for (const double x : k) ss += (x - s.mean) * (x - s.mean);
  s.sample_std = std::sqrt(ss / (n - 1));
  if (std::any_of(se.begin(), se.end(), [](double u) { return !(u > 0); })) return s;
  const double weighted_mean = wk_sum / w_sum;
  double chi2 = 0;
  for (std::size_t i = 0; i < k.size(); ++i) chi2 += std::pow((k[i] - weighted_mean) / se[i], 2);
  s.chi2 = chi2;
  s.birge_ratio = std::sqrt(chi2 / (n - 1));
  return s;
}

// The terms most calibrations used (ties: the newest's): a refit with other terms must not
// decide which coefficients the scatter compares.
std::string most_common_terms(const std::vector<Calibration>& cals) {
  std::map<std::string, int> count;
  for (const auto& c : cals) ++count[c.fit->terms];
  std::string best;
  int best_n = 0;
  for (const auto& c : cals) {  // oldest first, so >= lets the newest win a tie
    if (count[c.fit->terms] >= best_n) {
      best = c.fit->terms;
      best_n = count[c.fit->terms];
    }
  }
  return best;
}

void flag_drift(const SerialFitRow& now, const SerialFitRow& prev, std::vector<DriftFlag>& out) {
  for (const std::string name : {"k1", "k0"}) {
    const auto a = now.coefficient(name), ua = now.std_error(name);
    const auto b = prev.coefficient(name), ub = prev.std_error(name);
    if (!a || !ua || !b || !ub) continue;
    const auto zeta = zeta_score(*a, *ua, *b, *ub);
    if (zeta && std::abs(*zeta) > kDriftZetaLimit)
      out.push_back({now.fit_id, prev.fit_id, name, *a - *b, *zeta});
  }
}

}  // namespace

std::optional<double> zeta_score(double k_new, double se_new, double k_prev, double se_prev) {
  const double u = std::sqrt(se_new * se_new + se_prev * se_prev);
  if (!(u > 0)) return std::nullopt;
  return (k_new - k_prev) / u;
}

SerialHistoryStats serial_history_stats(const std::vector<SerialFitRow>& fits) {
  SerialHistoryStats h;
  h.calibrations = calibrations_of(fits);
  if (h.calibrations.empty()) return h;
  h.terms = most_common_terms(h.calibrations);
  for (const char* name : {"k1", "k0"})
    h.scatter.push_back(scatter_of(h.calibrations, h.terms, name));
  // Each calibration against the last earlier one with the same terms (k1 of a dT-only fit
  // and of a dT + gradT fit are different quantities).
  for (std::size_t i = 1; i < h.calibrations.size(); ++i) {
    const auto& now = *h.calibrations[i].fit;
    for (std::size_t j = i; j-- > 0;) {
      if (h.calibrations[j].fit->terms != now.terms) continue;
      flag_drift(now, *h.calibrations[j].fit, h.flags);
      break;
    }
  }
  return h;
}

}  // namespace station
