// The paper's temperature cycle on one simulated gyro, in process: the chamber air follows the
// protocol's setpoint ramps (station/protocols/paper.toml: 25 -> -40 C at 60 C/h, record while
// heating to +70 C at 10 C/h) through the simulated chamber's first-order air lag, the gyro is
// the counter-board simulator's RlgGyroModel (thermal lag, thermal bias, IEEE 952 noise, pulse
// quantisation), and its net pulses are averaged into 600 s bins as the station bins them.
#pragma once

#include <cmath>
#include <cstdint>

#include "compensation/fit.hpp"
#include "sim_devices/counter_board_gyro.hpp"

namespace station::test {

inline constexpr double kBinS = 600.0;
inline constexpr double kAirTauS = 120.0;  // ChamberSimConfig::air_tau_s

/// Setpoint of the paper protocol at time t_s from the start of the cool-down, C; and the time
/// the heating ramp starts. Air follows it with a first-order lag.
struct PaperProfile {
  double start_c = 25.0, low_c = -40.0, high_c = 70.0;
  double cool_c_per_h = 60.0, heat_c_per_h = 10.0, tolerance_c = 0.5;
};

/// Bins (bias = bin mean rate, Earth rate 0) of one gyro over the record window of the paper
/// cycle: from the air reaching low_c (within tolerance) to it reaching high_c.
inline compensation::ModelData paper_cycle_bins(const sim::GyroConfig& gyro,
                                                const PaperProfile& p = {}) {
  sim::RlgGyroModel model(gyro);
  double air_c = p.start_c, setpoint_c = p.start_c, t_s = 0;
  bool heating = false, recording = false;
  double bin_start_s = 0, sum_a = 0, sum_grad = 0;
  std::int64_t bin_pulses0 = 0;
  int n = 0;
  compensation::ModelData d;
  const double lag = 1.0 - std::exp(-1.0 / kAirTauS);
  while (true) {
    t_s += 1.0;
    if (!heating) setpoint_c = std::max(p.low_c, setpoint_c - p.cool_c_per_h / 3600.0);
    if (heating) setpoint_c = std::min(p.high_c, setpoint_c + p.heat_c_per_h / 3600.0);
    air_c += (setpoint_c - air_c) * lag;
    model.step_to(t_s, air_c);
    if (!heating && std::abs(air_c - p.low_c) <= p.tolerance_c) {
      heating = recording = true;  // record_start, then the heating step
      bin_start_s = t_s;
      bin_pulses0 = model.net_pulses();
      continue;
    }
    if (!recording) continue;
    if (std::abs(air_c - p.high_c) <= p.tolerance_c) break;  // record_stop
    sum_a += model.temp_a_c();
    sum_grad += model.grad_t_c();
    if (++n < static_cast<int>(kBinS)) continue;
    // 1 deg/h == 1 arcsec/s: the bin's mean rate is its net angle over its length.
    const double angle_arcsec =
        static_cast<double>(model.net_pulses() - bin_pulses0) * gyro.pulse_weight_arcsec;
    d.bias_dph.push_back(angle_arcsec / kBinS - gyro.earth_rate_dph);
    d.temp_c.push_back(sum_a / n);
    d.grad_c.push_back(sum_grad / n);
    d.dtdt_c_per_h.push_back(0.0);
    d.channel.push_back(0.0);
    d.t_mid_s.push_back(bin_start_s + kBinS / 2);
    bin_start_s = t_s;
    bin_pulses0 = model.net_pulses();
    sum_a = sum_grad = 0;
    n = 0;
  }
  return d;
}

}  // namespace station::test
