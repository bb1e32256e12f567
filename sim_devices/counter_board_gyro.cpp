// RLG physics for the counter-board simulator: two-node thermal lag, thermal bias, IEEE 952 noise.
#include "sim_devices/counter_board_gyro.hpp"

#include <cmath>

namespace station::sim {

RlgGyroModel::RlgGyroModel(const GyroConfig& config)
    : config_(config),
      rng_(config.seed),
      temp_a_c_(config.thermal.initial_c),
      temp_b_c_(config.thermal.initial_c),
      power_rng_(config.seed ^ 0x5EED0F7E57ULL) {
  power_up();
}

void RlgGyroModel::power_up() {
  // IEEE 647 turn-on-to-turn-on repeatability: a bias drawn anew at each turn-on.
  std::normal_distribution<double> n(0.0, 1.0);
  power_ups_.push_back({time_s_, config_.acceptance.turn_on_sigma_dph * n(power_rng_)});
}

void RlgGyroModel::set_powered(bool on) {
  if (on && !powered_) power_up();
  powered_ = on;
}

double RlgGyroModel::power_bias_dph(double from_s, double dt_s) const {
  const PowerUp& p = power_ups_.back();
  const double since_s = from_s - p.t_s;
  return p.turn_on_bias_dph + warmup_mean_dph(config_.acceptance, since_s, since_s + dt_s);
}

double RlgGyroModel::table_input_arcsec(double from_deg, double to_deg, double dt_s) const {
  // The table's turn along the input axis, through the scale factor (IEEE 647: output =
  // (1 + SF error) * input, the error a function of rate, temperature and sign).
  const auto& a = config_.acceptance;
  const double input_deg = table_coupling(a) * (to_deg - from_deg);
  const double dt_c = temp_a_c_ - config_.coefficients.ref_temp_c;
  const double sf_ppm = scale_factor_error_ppm(a, input_deg / dt_s, dt_c);
  return input_deg * 3600.0 * (1.0 + 1e-6 * sf_ppm);
}

double RlgGyroModel::thermal_bias_dph() const {
  // The paper's model: B = B0 + k1*dT + k2*dT^2 + k0*gradT with dT = T_A - T_ref.
  const auto& c = config_.coefficients;
  const double dt_c = temp_a_c_ - c.ref_temp_c;
  return c.B0_dph + c.k1 * dt_c + c.k2 * dt_c * dt_c + c.k0 * grad_t_c();
}

void RlgGyroModel::step_to(double sim_time_s, double chamber_air_c) {
  const double step = config_.step_s;
  while (sim_time_s - time_s_ >= step - 1e-9) advance(step, chamber_air_c);
  if (sim_time_s - time_s_ > 1e-9) advance(sim_time_s - time_s_, chamber_air_c);
}

double RlgGyroModel::noise_rate_dph(double dt_s) {
  const auto& n = config_.noise;
  // White rate noise from ARW (IEEE 952 annex C): N deg/sqrt(h) = 60*N deg/h/sqrt(Hz), so the
  // mean rate over dt seconds has sigma = 60*N/sqrt(dt) deg/h.
  const double white = 60.0 * n.arw_dpsh / std::sqrt(dt_s) * normal_(rng_);
  // Bias instability as a first-order Gauss-Markov process (exact discretisation).
  const double a = std::exp(-dt_s / n.bias_corr_time_s);
  gauss_markov_dph_ =
      a * gauss_markov_dph_ + n.bias_instability_dph * std::sqrt(1.0 - a * a) * normal_(rng_);
  // Rate random walk: K deg/h/sqrt(h) gives a rate increment of sigma K*sqrt(dt/3600 h).
  rrw_dph_ += n.rrw_dph_psh * std::sqrt(dt_s / 3600.0) * normal_(rng_);
  return white + gauss_markov_dph_ + rrw_dph_;
}

void RlgGyroModel::advance(double dt_s, double air_c) {
  // Series first-order lags: air -> A (housing) -> B (core). The housing step is exact for air
  // held over the step; the core step drives B with the midpoint of A over the step, an
  // approximation (good while dt << tau_housing_s), not the exact two-node solution.
  // Under a ramp r C/s the steady gradient is A - B = r * tau_core_s.
  const double a_old = temp_a_c_;
  temp_a_c_ += (air_c - temp_a_c_) * (1.0 - std::exp(-dt_s / config_.thermal.tau_housing_s));
  const double a_mid = 0.5 * (a_old + temp_a_c_);
  temp_b_c_ += (a_mid - temp_b_c_) * (1.0 - std::exp(-dt_s / config_.thermal.tau_core_s));

  const double from_s = time_s_;
  const double noise_dph = noise_rate_dph(dt_s);  // drawn powered or not: one noise stream
  time_s_ += dt_s;
  if (!powered_) return;  // no discharge, no dither: no pulses
  const auto& table = config_.table_angle_deg;
  const double from_deg = table ? table(from_s) : 0.0;
  const double to_deg = table ? table(from_s + dt_s) : 0.0;
  // Only the table's part goes through the scale-factor error. The Earth rate and the bias stay
  // at the nominal scale, so the thermal truth is what TrueCoefficients states: scaled, a
  // temperature-dependent SF error eps(T) would add eps(T)*W*sin(lat) (~5e-5 deg/h per C at
  // 5 ppm/C) that a fit takes into B0 and k1. The station's bias is output minus Earth rate
  // (compensation/earth_rate.hpp) in the same nominal units.
  const double earth_dph = earth_rate_along_input_dph(
      config_.acceptance, config_.earth_rate_dph, config_.earth_rate_north_dph, from_deg, to_deg);
  const double rate_dph = earth_dph + thermal_bias_dph() + power_bias_dph(from_s, dt_s) + noise_dph;
  // 1 deg/h == 1 arcsec/s; a table at rest adds exactly 0.
  const double dangle_arcsec = rate_dph * dt_s + table_input_arcsec(from_deg, to_deg, dt_s);
  angle_arcsec_ += dangle_arcsec;
  count_pulses(dangle_arcsec, dt_s);
}

void RlgGyroModel::count_pulses(double dangle_arcsec, double dt_s) {
  residual_pulses_ += dangle_arcsec / config_.pulse_weight_arcsec;
  const double whole = std::floor(residual_pulses_);
  residual_pulses_ -= whole;  // carry the fraction so no angle is lost
  const auto k = static_cast<std::int64_t>(whole);
  net_pulses_ += k;
  if (k > 0) up_pulses_ += static_cast<std::uint64_t>(k);
  if (k < 0) down_pulses_ += static_cast<std::uint64_t>(-k);

  dither_residual_ += config_.dither_pulses_per_s * dt_s;
  const double d = std::floor(dither_residual_);
  dither_residual_ -= d;
  dither_pulses_ += static_cast<std::uint64_t>(d);
}

}  // namespace station::sim
