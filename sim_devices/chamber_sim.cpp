// ChamberSim: fixed-step thermal model and its register view.
#include "sim_devices/chamber_sim.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"

namespace station::sim {
namespace cm = drivers::chamber_map;

ChamberSim::ChamberSim(drivers::modbus::RegisterMap map, ChamberSimConfig cfg)
    : map_(std::move(map)),
      cfg_(cfg),
      air_c_(cfg.initial_c),
      product_c_(cfg.initial_c),
      setpoint_c_(cfg.initial_c),
      effective_sp_c_(cfg.initial_c),
      run_(cfg.initial_run) {}

void ChamberSim::step_to(double sim_time_s) {
  std::lock_guard lock(mutex_);
  while (t_s_ + 1e-9 < sim_time_s) {
    double dt = std::min(cfg_.step_s, sim_time_s - t_s_);
    step_once(dt);
    t_s_ += dt;
  }
}

void ChamberSim::step_once(double dt) {
  bool driving = run_ && !high_limit_;
  if (driving && !hold_) {
    // Setpoint ramp: effective setpoint moves toward the target at ramp rate; 0 = step.
    double max_step = ramp_c_per_min_ / 60.0 * dt;
    double diff = setpoint_c_ - effective_sp_c_;
    effective_sp_c_ = ramp_c_per_min_ <= 0
                          ? setpoint_c_
                          : effective_sp_c_ + std::clamp(diff, -max_step, max_step);
  }
  double target = driving ? effective_sp_c_ : cfg_.ambient_c;
  // Exact first-order step toward a constant target: x += (target - x)(1 - e^{-dt/tau}).
  double d_air = (target - air_c_) * (1.0 - std::exp(-dt / cfg_.air_tau_s));
  d_air = std::clamp(d_air, -cfg_.cool_rate_c_per_min / 60.0 * dt,
                     cfg_.heat_rate_c_per_min / 60.0 * dt);
  air_c_ += d_air;
  product_c_ += (air_c_ - product_c_) * (1.0 - std::exp(-dt / cfg_.product_tau_s));
}

double ChamberSim::sim_time_s() const {
  std::lock_guard lock(mutex_);
  return t_s_;
}

double ChamberSim::air_c() const {
  std::lock_guard lock(mutex_);
  return air_c_;
}

double ChamberSim::product_c() const {
  std::lock_guard lock(mutex_);
  return product_c_;
}

double ChamberSim::effective_setpoint_c() const {
  std::lock_guard lock(mutex_);
  return effective_sp_c_;
}

void ChamberSim::set_air_sensor_failed(bool failed) {
  std::lock_guard lock(mutex_);
  sensor_failed_ = failed;
}

void ChamberSim::set_air_shown_c(std::optional<double> c) {
  std::lock_guard lock(mutex_);
  air_shown_c_ = c;
}

double ChamberSim::shown_air_c() const {
  std::lock_guard lock(mutex_);
  return air_shown_c_.value_or(air_c_);
}

void ChamberSim::set_door_open(bool open) {
  std::lock_guard lock(mutex_);
  door_open_ = open;
}

void ChamberSim::set_high_limit_trip(bool tripped) {
  std::lock_guard lock(mutex_);
  high_limit_ = tripped;
}

void ChamberSim::set_hold(bool hold) {
  std::lock_guard lock(mutex_);
  hold_ = hold;
}

void ChamberSim::set_setpoint_c(double setpoint_c) {
  std::lock_guard lock(mutex_);
  if (std::isfinite(setpoint_c))
    setpoint_c_ = std::clamp(setpoint_c, cfg_.setpoint_low_c, cfg_.setpoint_high_c);
}

double ChamberSim::setpoint_c() const {
  std::lock_guard lock(mutex_);
  return setpoint_c_;
}

unsigned ChamberSim::alarms() const {
  std::lock_guard lock(mutex_);
  return alarms_locked();
}

void ChamberSim::set_run_locked(bool run) {
  // A Watlow ramp starts from the process value when the output is enabled.
  if (run && !run_) effective_sp_c_ = air_c_;
  run_ = run;
}

bool ChamberSim::run() const {
  std::lock_guard lock(mutex_);
  return run_;
}

void ChamberSim::set_run(bool run) {
  std::lock_guard lock(mutex_);
  set_run_locked(run);
}

double ChamberSim::ramp_c_per_min() const {
  std::lock_guard lock(mutex_);
  return ramp_c_per_min_;
}

void ChamberSim::set_ramp_c_per_min(double ramp) {
  std::lock_guard lock(mutex_);
  if (std::isfinite(ramp) && ramp >= 0) ramp_c_per_min_ = ramp;
}

int ChamberSim::status() const {
  std::lock_guard lock(mutex_);
  return status_locked();
}

bool ChamberSim::air_sensor_failed() const {
  std::lock_guard lock(mutex_);
  return sensor_failed_;
}

int ChamberSim::status_locked() const {
  if (!run_ || high_limit_) return 0;
  if (hold_) return 3;
  return std::fabs(setpoint_c_ - effective_sp_c_) > 1e-9 ? 2 : 1;
}

unsigned ChamberSim::alarms_locked() const {
  unsigned bits = 0;
  if (run_ && std::fabs(air_c_ - effective_sp_c_) > cfg_.deviation_band_c) bits |= cm::kDeviation;
  if (sensor_failed_) bits |= cm::kSensorBreak;
  if (door_open_) bits |= cm::kDoorOpen;
  if (high_limit_) bits |= cm::kHighLimitTrip;
  return bits;
}

int ChamberSim::register_count() const {
  return sim::register_count(map_);
}

void ChamberSim::publish(modbus_mapping_t& regs) {
  std::lock_guard lock(mutex_);
  put_point(regs, map_.at(cm::kAir),
            sensor_failed_ ? cfg_.broken_sensor_c : air_shown_c_.value_or(air_c_));
  put_point(regs, map_.at(cm::kProduct), product_c_);
  put_point(regs, map_.at(cm::kStatus), status_locked());
  put_point(regs, map_.at(cm::kAlarms), alarms_locked());
  put_point(regs, map_.at(cm::kSetpoint), setpoint_c_);
  put_point(regs, map_.at(cm::kRamp), ramp_c_per_min_);
  put_point(regs, map_.at(cm::kSetpointLow), cfg_.setpoint_low_c);
  put_point(regs, map_.at(cm::kSetpointHigh), cfg_.setpoint_high_c);
  put_point(regs, map_.at(cm::kRun), run_ ? 1 : 0);
}

std::uint8_t ChamberSim::check_write(const RegisterWrite& write) const {
  const auto run = write.value_of(map_.at(cm::kRun));
  if (run && *run != 0 && *run != 1) return kIllegalDataValue;
  const auto ramp = write.value_of(map_.at(cm::kRamp));
  if (ramp && !(std::isfinite(*ramp) && *ramp >= 0)) return kIllegalDataValue;
  const auto sp = write.value_of(map_.at(cm::kSetpoint));
  if (sp && !std::isfinite(*sp)) return kIllegalDataValue;
  return 0;
}

void ChamberSim::on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) {
  std::lock_guard lock(mutex_);
  const auto& sp = map_.at(cm::kSetpoint);
  if (point_written(sp, pdu_address, count) && std::isfinite(get_point(regs, sp))) {
    // The controller clamps to its own limits, as the F4 does.
    setpoint_c_ = std::clamp(get_point(regs, sp), cfg_.setpoint_low_c, cfg_.setpoint_high_c);
  }
  const auto& ramp = map_.at(cm::kRamp);
  if (point_written(ramp, pdu_address, count))
    ramp_c_per_min_ = std::max(0.0, get_point(regs, ramp));
  const auto& run = map_.at(cm::kRun);
  if (point_written(run, pdu_address, count)) set_run_locked(get_point(regs, run) != 0);
}

}  // namespace station::sim
