// Live bins: running sums per gyro, one bin closed when a sample falls past its window.
#include "station/live/live_bins.hpp"

#include <cmath>

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
  b.complete = n >= 0.9 * width_s_;  // min_fill 0.9 at the 1 s tick (compensation/binning.hpp)
  return b;
}

std::vector<std::pair<std::string, LiveBin>> LiveBins::add(const std::vector<SampleRow>& rows) {
  std::vector<std::pair<std::string, LiveBin>> closed;
  for (const auto& s : rows) {
    if (!s.recording || !s.rate_dph || !s.temp_c || !s.temp2_c || (s.flags & kUnfitFlags) != 0)
      continue;
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
    w.sum_grad += *s.temp2_c - *s.temp_c;  // gradient = second sensor − first (calibration.cpp)
  }
  return closed;
}

}  // namespace station::live
