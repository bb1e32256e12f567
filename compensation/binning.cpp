// Fixed-width binning with per-bin means and the least-squares temperature slope.
#include "compensation/binning.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace station::compensation {
namespace {

// Running sums of one bin; time is taken relative to the bin start for precision.
struct Sums {
  std::size_t n = 0;
  double t = 0, tt = 0, rate = 0, temp = 0, t_temp = 0, grad = 0, extra = 0;
};

void check_lengths(const BinInput& in) {
  const std::size_t n = in.time_s.size();
  if (in.rate_dph.size() != n || in.temp_c.size() != n ||
      (!in.grad_c.empty() && in.grad_c.size() != n) ||
      (!in.extra.empty() && in.extra.size() != n)) {
    throw std::invalid_argument("make_bins: series lengths differ");
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (!(in.time_s[i] > in.time_s[i - 1])) {
      throw std::invalid_argument("make_bins: time not increasing at sample " + std::to_string(i));
    }
  }
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
  if (!(cfg.width_s > 0)) throw std::invalid_argument("make_bins: bin width must be positive");
  check_lengths(in);
  std::vector<Bin> bins;
  if (in.time_s.empty()) return bins;
  const double period = effective_sample_period_s(in.time_s, cfg);
  const double expected = cfg.width_s / period;
  const double t0 = in.time_s.front();
  const double record_end = in.time_s.back() + period;
  const auto n_bins = static_cast<std::size_t>(std::floor((record_end - t0) / cfg.width_s + 1e-9));
  bins.reserve(n_bins);
  Sums s;
  std::size_t k = 0;
  for (std::size_t i = 0; i < in.time_s.size() && k < n_bins; ++i) {
    const auto bin_of = static_cast<std::size_t>((in.time_s[i] - t0) / cfg.width_s);
    while (k < bin_of && k < n_bins) {
      bins.push_back(finish(s, t0 + static_cast<double>(k) * cfg.width_s, expected, cfg.min_fill));
      s = Sums{};
      ++k;
    }
    if (k >= n_bins) break;
    const double t = in.time_s[i] - (t0 + static_cast<double>(k) * cfg.width_s);
    ++s.n;
    s.t += t;
    s.tt += t * t;
    s.rate += in.rate_dph[i];
    s.temp += in.temp_c[i];
    s.t_temp += t * in.temp_c[i];
    if (!in.grad_c.empty()) s.grad += in.grad_c[i];
    if (!in.extra.empty()) s.extra += in.extra[i];
  }
  if (k < n_bins)
    bins.push_back(finish(s, t0 + static_cast<double>(k) * cfg.width_s, expected, cfg.min_fill));
  return bins;
}

}  // namespace station::compensation
