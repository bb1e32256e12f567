// The report's figures from a run's stored record (Zhou et al. 2013, Figs. 2-5).
#include "station/report/report_data.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "compensation/binning.hpp"
#include "compensation/earth_rate.hpp"
#include "station/store/sample_series.hpp"

namespace station::report {

namespace sc = station::compensation;
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kSecondsPerHour = 3600.0;

Series points(std::string label, std::vector<double> x, std::vector<double> y) {
  Series s;
  s.label = std::move(label);
  s.x = std::move(x);
  s.y = std::move(y);
  return s;
}

/// Mean chamber air over [t0, t1) of the rows (NaN when none answered); `from` walks forward.
double mean_air(const std::vector<SampleRow>& rows, std::size_t& from, double t0_s, double t1_s) {
  while (from < rows.size() && rows[from].t_s < t0_s) ++from;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = from; i < rows.size() && rows[i].t_s < t1_s; ++i) {
    if (rows[i].air_c) {
      sum += *rows[i].air_c;
      ++n;
    }
  }
  return n == 0 ? kNaN : sum / static_cast<double>(n);
}

}  // namespace

Figure make_figure(std::string id, std::string title, std::string x_label, std::string y_label,
                   std::string y2_label) {
  Figure f;
  f.id = std::move(id);
  f.title = std::move(title);
  f.x_label = std::move(x_label);
  f.y_label = std::move(y_label);
  f.y2_label = std::move(y2_label);
  return f;
}

std::size_t Figure::points() const {
  std::size_t n = 0;
  for (const auto& s : series)
    n += static_cast<std::size_t>(
        std::count_if(s.y.begin(), s.y.end(), [](double v) { return std::isfinite(v); }));
  return n;
}

std::vector<RunBin> whole_run_bins(const std::vector<SampleRow>& rows, double bin_s,
                                   double earth_rate_dph) {
  const SampleSeries s = sample_series(rows, SampleRule::usable);
  sc::BinConfig cfg;
  cfg.width_s = bin_s;
  cfg.sample_period_s = 1.0;  // the sequencer's tick
  std::vector<RunBin> out;
  if (s.t_s.size() < 2) return out;
  std::size_t air_from = 0;
  for (const auto& b : sc::make_bins(s.bin_input(), cfg)) {
    if (!b.complete) continue;
    out.push_back({b.t_mid_s, compensation::bias_dph(b.rate_dph, earth_rate_dph), b.temp_c,
                   mean_air(rows, air_from, b.t_start_s, b.t_start_s + bin_s), b.dtdt_c_per_h});
  }
  return out;
}

Figure figure_2a(const std::vector<RunBin>& bins, double bin_s) {
  Figure f =
      make_figure("2a", fmt::format("Bias ({:g} s bins) and temperatures against time", bin_s),
                  "time (h)", "bias (\u00b0/h)", "temperature (\u00b0C)");
  Series bias = points("bias", {}, {}), gyro = points("gyro temperature", {}, {}),
         air = points("chamber air", {}, {});
  for (const auto& b : bins) {
    const double t_h = b.t_mid_s / kSecondsPerHour;
    for (Series* s : {&bias, &gyro, &air}) s->x.push_back(t_h);
    bias.y.push_back(b.bias_dph);
    gyro.y.push_back(b.temp_c);
    air.y.push_back(b.air_c);
  }
  bias.line = gyro.line = air.line = true;
  gyro.second_y = air.second_y = true;
  f.series = {bias, gyro, air};
  return f;
}

Figure figure_2b(const std::vector<RunBin>& bins) {
  Figure f = make_figure("2b", "Bias against temperature: heating and cooling branches",
                         "gyro temperature (\u00b0C)", "bias (\u00b0/h)");
  Series heating = points("heating", {}, {}), cooling = points("cooling", {}, {}),
         steady = points("steady", {}, {});
  for (const auto& b : bins) {
    Series& s = b.dtdt_c_per_h > kBranchSlopeCPerH    ? heating
                : b.dtdt_c_per_h < -kBranchSlopeCPerH ? cooling
                                                      : steady;
    s.x.push_back(b.temp_c);
    s.y.push_back(b.bias_dph);
  }
  f.series = {heating, cooling, steady};
  return f;
}

Figure figure_3(const std::vector<RampRun>& ramps) {
  Figure f =
      make_figure("3", "Bias against temperature at 0, 10 and 20 \u00b0C/h (hysteresis study)",
                  "gyro temperature (\u00b0C)", "bias (\u00b0/h)");
  std::vector<std::string> missing{"ramp_00", "ramp_10", "ramp_20"};
  for (const auto& r : ramps) {
    f.series.push_back(points(r.protocol + " (run " + std::to_string(r.run_id) + ")", r.data.temp_c,
                              r.data.bias_dph));
    std::erase(missing, r.protocol);
  }
  if (ramps.empty()) {
    f.note =
        "No ramp_00, ramp_10 or ramp_20 run of this serial in the database: run those protocols "
        "(station run --protocol ramp_10 ...) to draw the hysteresis study.";
  } else if (!missing.empty()) {
    std::string names;
    for (const auto& m : missing) names += (names.empty() ? "" : ", ") + m;
    f.note = "No run of " + names + " for this serial in the database.";
  }
  return f;
}

std::vector<double> model_part(const sc::FitResult& fit, const sc::ModelInput& data,
                               const std::vector<std::string>& keep) {
  sc::FitResult part = fit;
  for (std::size_t i = 0; i < part.names.size(); ++i)
    if (std::find(keep.begin(), keep.end(), part.names[i]) == keep.end())
      part.coefficients[i] = 0.0;
  return sc::predict(part, data);
}

std::vector<std::string> temperature_terms(const sc::FitResult& fit) {
  std::vector<std::string> out;
  for (const auto& n : fit.names)
    if (n == "k1" || n == "k2" || n == "k3" || n == "k4") out.push_back(n);
  return out;
}

Figure figure_4(const sc::FitResult& fit, const sc::ModelData& data) {
  Figure f = make_figure("4", "Bias after removing k1\u00b7\u0394T against the gradient \u2207T",
                         "gradient \u2207T = T2 \u2212 T1 (\u00b0C)",
                         "bias \u2212 k1\u00b7\u0394T (\u00b0/h)");
  const auto temps = model_part(fit, data.view(), temperature_terms(fit));
  std::vector<double> y(data.bias_dph.size());
  for (std::size_t i = 0; i < y.size(); ++i) y[i] = data.bias_dph[i] - temps[i];
  f.series.push_back(points("bias - k1\u00b7\u0394T", data.grad_c, y));
  const bool has_k0 = std::find(fit.names.begin(), fit.names.end(), "k0") != fit.names.end();
  if (has_k0) {
    Series line = points("B0 + k0\u00b7\u2207T (fit)", data.grad_c,
                         model_part(fit, data.view(), {"B0", "k0"}));
    line.line = true;
    f.series.push_back(line);
  } else {
    f.note = "The fit has no gradient term (k0): no line drawn.";
  }
  return f;
}

Figure figure_5a(const sc::FitResult& fit, const sc::ModelData& data) {
  Figure f = make_figure("5a", "Bias before and after compensation against temperature",
                         "gyro temperature (\u00b0C)", "bias (\u00b0/h)");
  auto kept = temperature_terms(fit);
  kept.insert(kept.begin(), "B0");
  const auto temps = model_part(fit, data.view(), kept);
  std::vector<double> after_dt(data.bias_dph.size());
  for (std::size_t i = 0; i < after_dt.size(); ++i) after_dt[i] = data.bias_dph[i] - temps[i];
  f.series = {points("before", data.temp_c, data.bias_dph),
              points("after \u0394T only", data.temp_c, after_dt),
              points("after \u0394T + \u2207T", data.temp_c, sc::compensate(fit, data.view()))};
  return f;
}

Figure figure_6(std::int64_t fit_id, const std::vector<double>& temp_c,
                const std::vector<double>& before_dph, const std::vector<double>& after_dph) {
  Figure f = make_figure("6",
                         fmt::format("Verification: bias before and after fit {} (fitted on other "
                                     "runs) against temperature",
                                     fit_id),
                         "gyro temperature (\u00b0C)", "bias (\u00b0/h)");
  f.series = {points("before", temp_c, before_dph),
              points(fmt::format("after fit {} (gyro_tc_correct)", fit_id), temp_c, after_dph)};
  return f;
}

}  // namespace station::report
