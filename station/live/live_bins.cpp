// Live bins: running sums per gyro, one bin closed when a sample falls past its window.
#include "station/live/live_bins.hpp"

#include <cmath>

#include "compensation/binning.hpp"

namespace station::live {

LiveBins::LiveBins(std::map<std::string, double> earth_rate_dph, double width_s)
    : earth_rate_dph_(std::move(earth_rate_dph)), width_s_(width_s) {}

LiveBin LiveBins::close(const std::string& serial, const Window& w) const {
  LiveBin b;
  const double n = w.n;
  const auto it = earth_rate_dph_.find(serial);
  b.t_mid_s = w.sum_t / n;
  b.temp_c = w.sum_temp / n;
  b.grad_c = w.sum_grad / n;
  b.bias_dph = w.sum_rate / n - (it == earth_rate_dph_.end() ? 0.0 : it->second);
  b.n = w.n;
  // The station's bin rule (compensation/binning.hpp) at the sequencer's 1 s tick.
  b.complete = n >= compensation::BinConfig{}.min_fill * width_s_;
  return b;
}

std::vector<std::pair<std::string, LiveBin>> LiveBins::add(const std::vector<SampleRow>& rows) {
  std::vector<std::pair<std::string, LiveBin>> closed;
  for (const auto& s : rows) {
    if (!sample_goes_into_bins(s)) continue;
    Window& w = open_[s.serial];
    if (!w.t0_s) w.t0_s = s.t_s;
    const long k = static_cast<long>(std::floor((s.t_s - *w.t0_s) / width_s_));
    if (k != w.k) {
      if (w.n > 0) {
        closed.emplace_back(s.serial, close(s.serial, w));
        done_[s.serial].push_back(closed.back().second);
      }
      w = Window{w.t0_s, k};
    }
    ++w.n;
    w.sum_t += s.t_s;
    w.sum_rate += *s.rate_dph;
    w.sum_temp += *s.temp_c;
    w.sum_grad += *gradient_c(s);
  }
  return closed;
}

}  // namespace station::live
