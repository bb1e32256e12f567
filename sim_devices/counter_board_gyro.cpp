// RLG physics for the counter-board simulator: two-node thermal lag, thermal bias, IEEE 952 noise.
#include "sim_devices/counter_board_gyro.hpp"

#include <cmath>

namespace station::sim {

RlgGyroModel::RlgGyroModel(const GyroConfig& config)
    : config_(config),
      rng_(config.seed),
      temp_a_c_(config.thermal.initial_c),
      temp_b_c_(config.thermal.initial_c) {}

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

  const double rate_dph = config_.earth_rate_dph + thermal_bias_dph() + noise_rate_dph(dt_s);
  const double dangle_arcsec = rate_dph * dt_s;  // 1 deg/h == 1 arcsec/s
  angle_arcsec_ += dangle_arcsec;
  time_s_ += dt_s;

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
