// Live 600 s bins for the page, computed as ticks arrive: one running window per gyro, the
// same sample filter as the stored bins (calibration.hpp: recording, rate and both temperatures
// present, no kUnfitFlags) and bias = mean rate − the slot's Earth rate (paper §2). Windows are
// w wide from the first usable sample. Display only: the fit uses the bins stored at the end.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "station/store/store.hpp"

namespace station::live {

/// One live bin.
struct LiveBin {
  double t_mid_s = 0, temp_c = 0, grad_c = 0, bias_dph = 0;
  int n = 0;
  bool complete = false;  ///< n >= 0.9 · w / 1 s (the stored bins' min_fill)
};

/// Running bins of every gyro of one run.
class LiveBins {
 public:
  /// `earth_rate_dph` per serial; `width_s` the station's bin width.
  LiveBins(std::map<std::string, double> earth_rate_dph, double width_s);
  /// Adds one tick's samples; returns the bins this tick completed, as (serial, bin).
  std::vector<std::pair<std::string, LiveBin>> add(const std::vector<SampleRow>& rows);
  /// Every closed bin so far, per serial.
  const std::map<std::string, std::vector<LiveBin>>& bins() const { return done_; }

 private:
  struct Window {
    std::optional<double> t0_s;  ///< first usable sample: window k is [t0 + k w, t0 + (k+1) w)
    long k = 0;
    int n = 0;
    double sum_t = 0, sum_rate = 0, sum_temp = 0, sum_grad = 0;
  };
  LiveBin close(const std::string& serial, const Window& w) const;

  std::map<std::string, double> earth_rate_dph_;
  double width_s_;
  std::map<std::string, Window> open_;
  std::map<std::string, std::vector<LiveBin>> done_;
};

}  // namespace station::live
