// Simulated ring laser gyro behind a counter board: thermal bias model, noise, pulse quantisation,
// and (issue 36) the table it sits on, its scale factor, power, turn-on bias and warm-up.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "sim_devices/gyro_acceptance.hpp"

namespace station::sim {

/// The true thermal-bias coefficients (the paper's model B = B0 + k1*dT + k2*dT^2 + k0*gradT).
struct TrueCoefficients {
  double B0_dph = 0.05;      ///< bias at the reference temperature, deg/h
  double k1 = 1.0e-3;        ///< deg/h per C of dT = T_A - ref_temp_c
  double k2 = 2.0e-5;        ///< deg/h per C^2
  double k0 = 0.02;          ///< deg/h per C of gradT = T_B - T_A (second sensor minus first)
  double ref_temp_c = 25.0;  ///< reference temperature of dT, C
};

/// Two-node thermal model: air -> housing (sensor A) -> core (sensor B), first order each.
struct ThermalParams {
  double tau_housing_s = 1200.0;  ///< housing time constant, s (~20 min)
  double tau_core_s = 3600.0;     ///< core time constant behind the housing, s (~60 min)
  double initial_c = 25.0;        ///< both nodes start here, C
};

/// Noise terms in IEEE 952 / IEEE 647 units.
struct NoiseParams {
  double arw_dpsh = 0.003;              ///< angle random walk N, deg/sqrt(h)
  double bias_instability_dph = 0.003;  ///< Gauss-Markov steady-state sigma, deg/h
  double bias_corr_time_s = 3600.0;     ///< Gauss-Markov correlation time, s
  double rrw_dph_psh = 1.0e-4;          ///< rate random walk K, deg/h/sqrt(h)
};

/// The table's unwrapped angle at a simulated time, deg, right-handed about up
/// (TurntableSim::cumulative_angle_at_deg); called only for times the gyro steps through.
using TableAngleFn = std::function<double(double sim_time_s)>;

/// Everything one simulated gyro needs.
struct GyroConfig {
  TrueCoefficients coefficients;
  ThermalParams thermal;
  NoiseParams noise;
  AcceptanceTruth acceptance;  ///< scale factor, turn-on, warm-up, mounting (default: none)
  /// Earth rate's vertical component (W sin(lat)), deg/h, from the caller: for the default
  /// mounting (input axis up, no misalignment) the Earth rate along the input axis.
  double earth_rate_dph = 0.0;
  double earth_rate_north_dph = 0.0;   ///< its north component (W cos(lat)), deg/h
  TableAngleFn table_angle_deg;        ///< the table the gyro is mounted on; empty: at rest
  double pulse_weight_arcsec = 1.5;    ///< angle per net pulse, arcsec
  double dither_pulses_per_s = 2.0e4;  ///< pulses each counter counts from dither, per s
  double step_s = 1.0;                 ///< internal integration step, s
  std::uint64_t seed = 1;              ///< std::mt19937_64 seed
};

/// One RLG integrated on simulated time only. Deterministic for a given config and call sequence.
class RlgGyroModel {
 public:
  /// Sets up the model at time 0 (no I/O).
  explicit RlgGyroModel(const GyroConfig& config);

  /// Advances to sim_time_s (s) in internal steps of step_s (last one shorter) with air at air_c.
  void step_to(double sim_time_s, double chamber_air_c);

  /// Simulated time reached, s.
  double time_s() const { return time_s_; }
  /// Housing (sensor A, TEMPS channel 0) and core (sensor B, channel 1) temperatures, C.
  /// gradT = B - A: second sensor minus first, the convention of `station analyze --temp2-col`
  /// and of the station's samples (temp2_c - temp_c); dT is taken from sensor A.
  double temp_a_c() const { return temp_a_c_; }
  double temp_b_c() const { return temp_b_c_; }
  double grad_t_c() const { return temp_b_c_ - temp_a_c_; }
  /// Deterministic thermal bias at the current temperatures, deg/h (no noise, no Earth rate).
  double thermal_bias_dph() const;
  /// Switches the gyro's power at time_s(). Off: no pulses at all, dither included (the
  /// temperatures and the noise processes go on). Off to on: a new turn-on bias drawn from
  /// N(0, turn_on_sigma_dph) and the warm-up transient restarts. Powered from time 0, which
  /// counts as a power-up.
  void set_powered(bool on);
  bool powered() const { return powered_; }
  /// Every power-up so far, the first at time 0.
  const std::vector<PowerUp>& power_ups() const { return power_ups_; }
  /// True integrated angle since time 0 as the gyro sensed it while powered (table through the
  /// scale factor, Earth rate, bias, noise), arcsec.
  double true_angle_arcsec() const { return angle_arcsec_; }
  /// Net pulses emitted since time 0: floor(true angle / pulse weight), remainder carried.
  std::int64_t net_pulses() const { return net_pulses_; }
  /// Cumulative dither pulses counted by each counter since time 0.
  std::uint64_t dither_pulses() const { return dither_pulses_; }
  /// Cumulative up (positive rotation) and down pulses since time 0, excluding dither.
  std::uint64_t up_pulses() const { return up_pulses_; }
  std::uint64_t down_pulses() const { return down_pulses_; }
  /// The configuration, including the true coefficients.
  const GyroConfig& config() const { return config_; }

 private:
  void advance(double dt_s, double air_c);
  double noise_rate_dph(double dt_s);
  double power_bias_dph(double from_s, double dt_s) const;
  double table_input_arcsec(double from_deg, double to_deg, double dt_s) const;
  void power_up();
  void count_pulses(double dangle_arcsec, double dt_s);

  GyroConfig config_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  double time_s_ = 0;
  double temp_a_c_, temp_b_c_;
  double gauss_markov_dph_ = 0, rrw_dph_ = 0;
  double angle_arcsec_ = 0, residual_pulses_ = 0, dither_residual_ = 0;
  std::int64_t net_pulses_ = 0;
  std::uint64_t dither_pulses_ = 0, up_pulses_ = 0, down_pulses_ = 0;
  // Power: its own random stream, so the noise is the same whatever the power does.
  std::mt19937_64 power_rng_;
  bool powered_ = true;
  std::vector<PowerUp> power_ups_;
};

}  // namespace station::sim
