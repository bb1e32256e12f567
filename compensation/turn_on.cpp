// Turn-on bias, warm-up time and turn-on-to-turn-on repeatability (definitions in turn_on.hpp).
#include "compensation/turn_on.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "compensation/chi_squared.hpp"
#include "compensation/limits.hpp"

namespace station::compensation {
namespace {

std::string series_problem(const TurnOnSeries& s) {
  if (s.t_s.size() != s.bias_dph.size())
    return std::to_string(s.t_s.size()) + " times but " + std::to_string(s.bias_dph.size()) +
           " biases";
  if (s.t_s.empty()) return "no bins";
  for (std::size_t j = 0; j < s.t_s.size(); ++j) {
    const std::string at = "bin " + std::to_string(j) + ": ";
    if (auto e = finite_problem(s.t_s[j]); !e.empty()) return at + "time " + e;
    if (auto e = rate_problem(s.bias_dph[j]); !e.empty()) return at + "bias " + e;
    if (j > 0 && !(s.t_s[j] > s.t_s[j - 1]))
      return at + "time " + number_text(s.t_s[j]) + " s is not after the previous bin's";
  }
  return {};
}

struct WindowMean {
  double mean = 0, se = 0;
  std::size_t n = 0;
};

// Mean and its SE (sample std / sqrt(n)) of the bins with start <= t <= end.
Computed<WindowMean> window_mean(const TurnOnSeries& s, double start_s, double end_s,
                                 const char* name) {
  if (!(std::isfinite(start_s) && std::isfinite(end_s) && start_s <= end_s))
    return NotComputed{std::string(name) + " window " + number_text(start_s) + ".." +
                       number_text(end_s) + " s is not an interval"};
  WindowMean m;
  double sum = 0;
  for (std::size_t j = 0; j < s.t_s.size(); ++j)
    if (s.t_s[j] >= start_s && s.t_s[j] <= end_s) sum += s.bias_dph[j], ++m.n;
  if (m.n < 2)
    return NotComputed{std::string(name) + " window " + number_text(start_s) + ".." +
                       number_text(end_s) + " s holds " + std::to_string(m.n) +
                       " bins; at least 2 needed"};
  m.mean = sum / static_cast<double>(m.n);
  double ss = 0;
  for (std::size_t j = 0; j < s.t_s.size(); ++j)
    if (s.t_s[j] >= start_s && s.t_s[j] <= end_s) ss += std::pow(s.bias_dph[j] - m.mean, 2);
  m.se = std::sqrt(ss / static_cast<double>(m.n - 1) / static_cast<double>(m.n));
  return m;
}

// Where d crosses the band between bin L (outside) and L+1 (inside), as a fraction of the
// interval: on ln|d| when both have the same sign (exact for an exponential), else linear.
double crossing_fraction(double d_out, double d_in, double band) {
  if (d_in != 0.0 && (d_in > 0) == (d_out > 0))
    return std::log(std::abs(d_out) / band) / std::log(std::abs(d_out) / std::abs(d_in));
  const double target = d_out > 0 ? band : -band;
  return (d_out - target) / (d_out - d_in);
}

}  // namespace

Computed<std::optional<double>> warmup_time_s(const TurnOnSeries& series, double final_dph,
                                              double band_dph) {
  if (auto e = series_problem(series); !e.empty()) return NotComputed{e};
  if (!(std::isfinite(band_dph) && band_dph > 0))
    return NotComputed{"band " + number_text(band_dph) + " deg/h is not a positive number"};
  if (auto e = finite_problem(final_dph); !e.empty()) return NotComputed{"final value " + e};
  const std::size_t n = series.t_s.size();
  std::optional<std::size_t> last_out;
  for (std::size_t j = 0; j < n; ++j)
    if (std::abs(series.bias_dph[j] - final_dph) > band_dph) last_out = j;
  if (!last_out) return std::optional<double>(series.t_s[0]);
  if (*last_out + 1 == n) return std::optional<double>();
  const std::size_t l = *last_out;
  const double frac = crossing_fraction(series.bias_dph[l] - final_dph,
                                        series.bias_dph[l + 1] - final_dph, band_dph);
  return std::optional<double>(series.t_s[l] + frac * (series.t_s[l + 1] - series.t_s[l]));
}

Computed<TurnOnFigures> analyze_turn_on(const TurnOnSeries& series, const TurnOnWindows& w) {
  if (auto e = series_problem(series); !e.empty()) return NotComputed{e};
  const auto bias = window_mean(series, w.bias_start_s, w.bias_end_s, "bias");
  if (!bias) return NotComputed{bias.error()};
  const auto final_value = window_mean(series, w.final_start_s, w.final_end_s, "final");
  if (!final_value) return NotComputed{final_value.error()};
  const auto warmup = warmup_time_s(series, final_value->mean, w.band_dph);
  if (!warmup) return NotComputed{warmup.error()};
  TurnOnFigures f;
  f.bias_dph = bias->mean;
  f.bias_se_dph = bias->se;
  f.bias_bins = bias->n;
  f.final_dph = final_value->mean;
  f.final_bins = final_value->n;
  f.warmup_s = *warmup;
  return f;
}

Computed<TurnOnRepeatability> turn_on_repeatability(std::span<const double> biases_dph,
                                                    double confidence, double quantization_dph) {
  if (!(confidence > 0 && confidence < 1))
    return NotComputed{"confidence " + number_text(confidence) + " is not within (0, 1)"};
  if (!(quantization_dph >= 0 && std::isfinite(quantization_dph)))
    return NotComputed{"quantization " + number_text(quantization_dph) +
                       " deg/h is not a number >= 0"};
  if (biases_dph.size() < 2)
    return NotComputed{std::to_string(biases_dph.size()) + " turn-ons; at least 2 needed"};
  for (std::size_t k = 0; k < biases_dph.size(); ++k)
    if (auto e = rate_problem(biases_dph[k]); !e.empty())
      return NotComputed{"turn-on " + std::to_string(k) + ": bias " + e};
  const double n = static_cast<double>(biases_dph.size());
  double mean = 0;
  for (double b : biases_dph) mean += b / n;
  double ss = 0;
  for (double b : biases_dph) ss += (b - mean) * (b - mean);
  TurnOnRepeatability r;
  r.turn_ons = biases_dph.size();
  r.dof = r.turn_ons - 1;
  r.mean_bias_dph = mean;
  r.repeatability_dph = std::sqrt(ss / (n - 1));
  r.confidence = confidence;
  // NIST/SEMATECH e-Handbook 1.3.5.8: (N-1) s^2 / sigma^2 ~ chi^2(N-1).
  const double dof = n - 1;
  const double q_hi = chi_squared_quantile(0.5 * (1 + confidence), dof);
  const double q_lo = chi_squared_quantile(0.5 * (1 - confidence), dof);
  r.repeatability_lower_dph = std::sqrt(ss / q_hi);
  r.repeatability_upper_dph = std::sqrt((ss + dof * quantization_dph * quantization_dph) / q_lo);
  return r;
}

Computed<TurnOnResult> analyze_turn_ons(std::span<const TurnOnSeries> turn_ons,
                                        const TurnOnWindows& w) {
  TurnOnResult out;
  std::vector<double> biases;
  double se2 = 0;
  for (std::size_t k = 0; k < turn_ons.size(); ++k) {
    const auto f = analyze_turn_on(turn_ons[k], w);
    if (!f) return NotComputed{"turn-on " + std::to_string(k) + ": " + f.error()};
    biases.push_back(f->bias_dph);
    se2 += f->bias_se_dph * f->bias_se_dph;
    if (!f->warmup_s)
      ++out.not_settled;
    else
      out.max_warmup_s = std::max(out.max_warmup_s.value_or(*f->warmup_s), *f->warmup_s);
    out.turn_ons.push_back(*f);
  }
  const auto rep = turn_on_repeatability(biases, w.confidence, w.bias_quantization_dph);
  if (!rep) return NotComputed{rep.error()};
  out.repeatability = *rep;
  out.mean_bias_se_dph = std::sqrt(se2 / static_cast<double>(turn_ons.size()));
  return out;
}

}  // namespace station::compensation
