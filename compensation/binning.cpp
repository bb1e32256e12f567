// Fixed-width binning with per-bin means and the least-squares temperature slope.
#include "compensation/binning.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "compensation/limits.hpp"

namespace station::compensation {
namespace {

// Running sums of one bin; time is taken relative to the bin start for precision.
struct Sums {
  std::size_t n = 0;
  double t = 0, tt = 0, rate = 0, temp = 0, t_temp = 0, grad = 0, extra = 0;
  double temp_min = 0, temp_max = 0, grad_min = 0, grad_max = 0;
};

// A bin index is an exact integer in a double only up to 2^53 (the binary64 significand).
constexpr double kMaxBins = 9007199254740992.0;

void check_finite(std::span<const double> v, const char* what) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      throw DataError("make_bins: " + std::string(what) + " of sample " + std::to_string(i) + ": " +
                      finite_problem(v[i]));
    }
  }
}

void check_input(const BinInput& in, const BinConfig& cfg) {
  if (!(cfg.width_s > 0) || !std::isfinite(cfg.width_s))
    throw DataError("make_bins: bin width must be a positive finite number");
  if (!(cfg.sample_period_s >= 0) || !std::isfinite(cfg.sample_period_s))
    throw DataError("make_bins: sample period must be a non-negative finite number");
  const std::size_t n = in.time_s.size();
  if (in.rate_dph.size() != n || in.temp_c.size() != n ||
      (!in.grad_c.empty() && in.grad_c.size() != n) ||
      (!in.extra.empty() && in.extra.size() != n)) {
    throw DataError("make_bins: series lengths differ");
  }
  check_finite(in.time_s, "time");
  check_finite(in.rate_dph, "rate");
  check_finite(in.temp_c, "temperature");
  check_finite(in.grad_c, "gradient");
  check_finite(in.extra, "extra channel");
  for (std::size_t i = 1; i < n; ++i) {
    if (!(in.time_s[i] > in.time_s[i - 1])) {
      throw DataError("make_bins: time not increasing at sample " + std::to_string(i));
    }
  }
}

void add(Sums& s, const BinInput& in, std::size_t i, double t_rel_s) {
  const double g = in.grad_c.empty() ? 0.0 : in.grad_c[i];
  if (s.n == 0) {
    s.temp_min = s.temp_max = in.temp_c[i];
    s.grad_min = s.grad_max = g;
  }
  s.temp_min = std::min(s.temp_min, in.temp_c[i]);
  s.temp_max = std::max(s.temp_max, in.temp_c[i]);
  s.grad_min = std::min(s.grad_min, g);
  s.grad_max = std::max(s.grad_max, g);
  ++s.n;
  s.t += t_rel_s;
  s.tt += t_rel_s * t_rel_s;
  s.rate += in.rate_dph[i];
  s.temp += in.temp_c[i];
  s.t_temp += t_rel_s * in.temp_c[i];
  if (!in.grad_c.empty()) s.grad += in.grad_c[i];
  if (!in.extra.empty()) s.extra += in.extra[i];
}

Bin finish(const Sums& s, double t_start_s, double expected, double min_fill) {
  Bin b;
  b.t_start_s = t_start_s;
  b.n = s.n;
  b.complete = s.n > 0 && static_cast<double>(s.n) >= min_fill * expected - 1e-9;
  if (s.n == 0) return b;
  const double n = static_cast<double>(s.n);
  b.t_mid_s = t_start_s + s.t / n;
  b.rate_dph = s.rate / n;
  b.temp_c = s.temp / n;
  b.grad_c = s.grad / n;
  b.extra = s.extra / n;
  b.temp_min_c = s.temp_min;
  b.temp_max_c = s.temp_max;
  b.grad_min_c = s.grad_min;
  b.grad_max_c = s.grad_max;
  // Ordinary least-squares slope: S_tT / S_tt with centred sums.
  const double s_tt = s.tt - s.t * s.t / n;
  const double s_tT = s.t_temp - s.t * s.temp / n;
  b.dtdt_c_per_h = s_tt > 0 ? 3600.0 * s_tT / s_tt : 0.0;
  return b;
}

}  // namespace

double effective_sample_period_s(std::span<const double> time_s, const BinConfig& cfg) {
  if (cfg.sample_period_s > 0) return cfg.sample_period_s;
  if (time_s.size() < 2) return cfg.width_s;
  std::vector<double> steps(time_s.size() - 1);
  for (std::size_t i = 1; i < time_s.size(); ++i) steps[i - 1] = time_s[i] - time_s[i - 1];
  auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), mid, steps.end());
  return *mid;
}

std::vector<Bin> make_bins(const BinInput& in, const BinConfig& cfg) {
  check_input(in, cfg);
  std::vector<Bin> bins;
  if (in.time_s.empty()) return bins;
  const double w = cfg.width_s;
  const double period = effective_sample_period_s(in.time_s, cfg);
  const double expected = w / period;
  const double t0 = in.time_s.front();
  const double span_bins = (in.time_s.back() + period - t0) / w;
  if (!(span_bins < kMaxBins)) {
    throw DataError("make_bins: the samples span " + number_text(in.time_s.back() - t0) +
                    " s, more than 2^53 bins of " + number_text(w) + " s");
  }
  // Bins 0 .. n_bins-1 end within the record; a later one is a trailing partial bin.
  const auto n_bins = static_cast<std::int64_t>(std::floor(span_bins + 1e-9));
  // Samples are in time order, so each bin's samples are consecutive: one pass, and a bin is
  // made only where a sample falls.
  Sums s;
  std::int64_t k = -1;
  auto close = [&] {
    if (s.n > 0) bins.push_back(finish(s, t0 + static_cast<double>(k) * w, expected, cfg.min_fill));
    s = Sums{};
  };
  for (std::size_t i = 0; i < in.time_s.size(); ++i) {
    const auto bin_of = static_cast<std::int64_t>((in.time_s[i] - t0) / w);
    if (bin_of >= n_bins) break;
    if (bin_of != k) {
      close();
      k = bin_of;
    }
    add(s, in, i, in.time_s[i] - (t0 + static_cast<double>(k) * w));
  }
  close();
  return bins;
}

}  // namespace station::compensation
