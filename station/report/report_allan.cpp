// Allan deviation of the 1 Hz record before and after compensation (the report's Fig. 5b).
#include "station/report/report_allan.hpp"

#include <algorithm>

#include "compensation/binning.hpp"
#include "compensation/earth_rate.hpp"
#include "station/store/sample_series.hpp"

namespace station::report {

namespace sc = station::compensation;
namespace {

bool has_coefficient(const sc::FitResult& fit, const char* name) {
  return std::find(fit.names.begin(), fit.names.end(), name) != fit.names.end();
}

/// dT/dt of each sample: the least-squares slope of the bin (bin_s wide) it falls in (what the fit
/// saw as its kr regressor), 0 outside a bin.
std::vector<double> per_sample_dtdt(const std::vector<double>& t_s,
                                    const std::vector<double>& temp_c, double bin_s) {
  std::vector<double> rate(t_s.size(), 0.0), out(t_s.size(), 0.0);
  sc::BinConfig cfg;
  cfg.width_s = bin_s;
  cfg.sample_period_s = 1.0;
  const auto bins = sc::make_bins({t_s, rate, temp_c, {}, {}}, cfg);
  std::size_t b = 0;
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    while (b < bins.size() && t_s[i] >= bins[b].t_start_s + bin_s) ++b;
    if (b < bins.size() && t_s[i] >= bins[b].t_start_s) out[i] = bins[b].dtdt_c_per_h;
  }
  return out;
}

}  // namespace

OneHzRecord one_hz_record(const std::vector<SampleRow>& rows, double earth_rate_dph,
                          const sc::FitResult& fit, double bin_s) {
  const SampleSeries s = sample_series(rows);
  const std::vector<double>&t = s.t_s, &temp = s.temp_c, &grad = s.grad_c;
  OneHzRecord r;
  for (double rate : s.rate_dph) r.bias_dph.push_back(compensation::bias_dph(rate, earth_rate_dph));
  if (r.bias_dph.empty()) return r;
  std::vector<double> dtdt, channel;
  if (has_coefficient(fit, "kr")) dtdt = per_sample_dtdt(t, temp, bin_s);
  if (has_coefficient(fit, "kc")) channel.assign(t.size(), 0.0);  // stored bins carry 0
  sc::ModelInput in;
  in.bias_dph = r.bias_dph;
  in.temp_c = temp;
  in.grad_c = grad;
  in.dtdt_c_per_h = dtdt;
  in.channel = channel;
  r.compensated_dph = sc::compensate(fit, in);  // bias - B(x), paper eq. (4)
  return r;
}

AllanCurves allan_curves(const OneHzRecord& record) {
  AllanCurves c;
  if (record.bias_dph.size() < 3) return c;
  constexpr double kRateHz = 1.0;        // the sequencer's tick
  constexpr double kConfidence = 0.683;  // 1 sigma, NIST SP 1065 section 5.3
  const auto m = sc::tau_factors(record.bias_dph.size(), sc::TauSpacing::octave);
  c.before = sc::overlapping_adev(record.bias_dph, kRateHz, m, kConfidence);
  c.after = sc::overlapping_adev(record.compensated_dph, kRateHz, m, kConfidence);
  c.noise_before = sc::fit_noise_terms(c.before);
  c.noise_after = sc::fit_noise_terms(c.after);
  return c;
}

Figure figure_5b(const AllanCurves& curves) {
  Figure f = make_figure("5b", "Allan deviation of the 1 Hz record before and after compensation",
                         "averaging time \u03c4 (s)", "Allan deviation (\u00b0/h)");
  f.log_axes = true;
  for (const auto* curve : {&curves.before, &curves.after}) {
    Series s;
    s.label = curve == &curves.before ? "before" : "after \u0394T + \u2207T";
    s.line = true;
    for (const auto& p : *curve) {
      s.x.push_back(p.tau_s);
      s.y.push_back(p.adev);
      s.y_low.push_back(p.ci_low);
      s.y_high.push_back(p.ci_high);
    }
    f.series.push_back(std::move(s));
  }
  // The IEEE 952 terms fitted to each curve, drawn as the curve they predict.
  for (const auto* curve : {&curves.before, &curves.after}) {
    const auto& terms = curve == &curves.before ? curves.noise_before : curves.noise_after;
    if (!terms.fit_chi2_per_dof) continue;
    Series s;
    s.label = curve == &curves.before ? "fitted terms (before)" : "fitted terms (after)";
    s.line = true;
    for (const auto& p : *curve) {
      s.x.push_back(p.tau_s);
      s.y.push_back(sc::noise_model_adev(terms, p.tau_s));
    }
    f.series.push_back(std::move(s));
  }
  if (curves.before.empty()) f.note = "Fewer than 3 usable 1 Hz samples in the record window.";
  return f;
}

}  // namespace station::report
