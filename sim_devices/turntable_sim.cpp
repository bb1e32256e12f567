// TurntableSim: velocity-limited, acceleration-limited motion (trapezoidal profile).
#include "sim_devices/turntable_sim.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/turntable/generic_plc/generic_plc_map.hpp"

namespace station::sim {
namespace tm = drivers::turntable_map;

namespace {
double wrap360(double a) {
  return std::fmod(std::fmod(a, 360.0) + 360.0, 360.0);
}
}  // namespace

TurntableSim::TurntableSim(drivers::modbus::RegisterMap map, TurntableSimConfig cfg)
    : map_(std::move(map)), cfg_(cfg) {}

void TurntableSim::step_to(double sim_time_s) {
  std::lock_guard lock(mutex_);
  while (t_s_ + 1e-9 < sim_time_s) {
    double dt = std::min(cfg_.step_s, sim_time_s - t_s_);
    step_once(dt);
    t_s_ += dt;
  }
}

double TurntableSim::velocity_demand() const {
  bool enabled = !interlock_open_ && !fault_ && !locked_ && !stopping_;
  if (!enabled || mode_ == 0) return 0.0;
  if (mode_ == 2)
    return std::clamp(rate_demand_dps_, -cfg_.max_rate_mode_dps, cfg_.max_rate_mode_dps);
  // Position: the fastest velocity from which the table can still stop at the target,
  // v = sqrt(2 a d), capped at the velocity limit; this yields the trapezoidal profile.
  double d = std::remainder(position_demand_deg_ - angle_deg_, 360.0);
  double v = std::min(cfg_.max_rate_dps, std::sqrt(2.0 * cfg_.max_accel_dps2 * std::fabs(d)));
  return std::copysign(v, d);
}

void TurntableSim::step_once(double dt) {
  double dv_max = cfg_.max_accel_dps2 * dt;
  double v_old = rate_dps_;
  double v_new = v_old + std::clamp(velocity_demand() - v_old, -dv_max, dv_max);
  track_step((v_new - v_old) / dt);
  // Trapezoidal integration: exact while the acceleration is constant over the step.
  double turned = 0.5 * (v_old + v_new) * dt;
  double next = angle_deg_ + turned;
  if (mode_ == 1 && !stopping_) {
    double before = std::remainder(position_demand_deg_ - angle_deg_, 360.0);
    double after = std::remainder(position_demand_deg_ - next, 360.0);
    // Do not overshoot the final approach: snap when the error changes sign at low speed (up
    // to two steps' worth of acceleration: with exactly one, rounding let a table coming from
    // rate mode hunt about its demand at that speed for ever, refusing the lock).
    if (before * after <= 0 && std::fabs(v_new) <= 2 * dv_max) {
      next = position_demand_deg_;
      turned = before;
      v_new = 0;
      snapped_ = true;
    }
  }
  cumulative_deg_ += turned;
  rate_dps_ = v_new;
  angle_deg_ = wrap360(next);
  if (stopping_ && rate_dps_ == 0) {
    stopping_ = false;
    mode_ = 0;
  }
  if ((interlock_open_ || fault_) && rate_dps_ == 0) mode_ = 0;
}

// A new track point at the start of a step whose acceleration differs from the one kept (at rest
// and at a steady rate it is exactly 0: no points), or after a snap.
void TurntableSim::track_step(double accel_dps2) {
  if (!snapped_ && accel_dps2 == track_.back().accel_dps2) return;
  snapped_ = false;
  track_.push_back({t_s_, cumulative_deg_, rate_dps_, accel_dps2});
}

double TurntableSim::cumulative_angle_deg() const {
  std::lock_guard lock(mutex_);
  return cumulative_deg_;
}

double TurntableSim::cumulative_angle_at_deg(double t_s) const {
  std::lock_guard lock(mutex_);
  if (t_s >= t_s_ - 1e-9) return cumulative_deg_;
  if (t_s <= track_.front().t_s) return track_.front().angle_deg;
  auto it = std::upper_bound(track_.begin(), track_.end(), t_s,
                             [](double t, const TrackPoint& p) { return t < p.t_s; });
  const TrackPoint& p = *std::prev(it);
  const double tau_s = t_s - p.t_s;
  // Constant acceleration from the point on (the trapezoid steps sum to exactly this).
  return p.angle_deg + p.rate_dps * tau_s + 0.5 * p.accel_dps2 * tau_s * tau_s;
}

void TurntableSim::forget_track_before(double t_s) {
  std::lock_guard lock(mutex_);
  auto it = std::upper_bound(track_.begin(), track_.end(), t_s,
                             [](double t, const TrackPoint& p) { return t < p.t_s; });
  if (it - track_.begin() > 1) track_.erase(track_.begin(), std::prev(it));
}

double TurntableSim::angle_deg() const {
  std::lock_guard lock(mutex_);
  return angle_deg_;
}

double TurntableSim::rate_dps() const {
  std::lock_guard lock(mutex_);
  return rate_dps_;
}

void TurntableSim::set_rate_shown_dps(std::optional<double> dps) {
  std::lock_guard lock(mutex_);
  rate_shown_dps_ = dps;
}

double TurntableSim::shown_rate_dps() const {
  std::lock_guard lock(mutex_);
  return rate_shown_dps_.value_or(rate_dps_);
}

void TurntableSim::set_interlock_open(bool open) {
  std::lock_guard lock(mutex_);
  interlock_open_ = open;
}

void TurntableSim::set_fault(bool fault) {
  std::lock_guard lock(mutex_);
  fault_ = fault;
}

unsigned TurntableSim::status_locked() const {
  unsigned bits = 0;
  double err = std::fabs(std::remainder(position_demand_deg_ - angle_deg_, 360.0));
  if (mode_ == 1 && err < cfg_.in_position_deg && std::fabs(rate_dps_) < cfg_.at_rate_dps)
    bits |= tm::kInPosition;
  if (mode_ == 2 && std::fabs(rate_dps_ - rate_demand_dps_) < cfg_.at_rate_dps) bits |= tm::kAtRate;
  if (fault_) bits |= tm::kFault;
  if (interlock_open_) bits |= tm::kInterlockOpen;
  return bits;
}

int TurntableSim::mode() const {
  std::lock_guard lock(mutex_);
  return mode_;
}

bool TurntableSim::set_mode(int mode) {
  std::lock_guard lock(mutex_);
  if (mode < 0 || mode > 2 || interlock_open_ || fault_) return false;
  mode_ = mode;
  stopping_ = false;
  return true;
}

double TurntableSim::position_demand_deg() const {
  std::lock_guard lock(mutex_);
  return position_demand_deg_;
}

double TurntableSim::rate_demand_dps() const {
  std::lock_guard lock(mutex_);
  return rate_demand_dps_;
}

void TurntableSim::set_position_demand_deg(double deg) {
  std::lock_guard lock(mutex_);
  if (std::isfinite(deg)) position_demand_deg_ = wrap360(deg);
}

void TurntableSim::set_rate_demand_dps(double dps) {
  std::lock_guard lock(mutex_);
  if (std::isfinite(dps)) rate_demand_dps_ = dps;
}

bool TurntableSim::interlock_open() const {
  std::lock_guard lock(mutex_);
  return interlock_open_;
}

bool TurntableSim::fault() const {
  std::lock_guard lock(mutex_);
  return fault_;
}

int TurntableSim::register_count() const {
  return sim::register_count(map_);
}

void TurntableSim::publish(modbus_mapping_t& regs) {
  std::lock_guard lock(mutex_);
  put_point(regs, map_.at(tm::kModeDemand), mode_);
  put_point(regs, map_.at(tm::kPositionDemand), position_demand_deg_);
  put_point(regs, map_.at(tm::kRateDemand), rate_demand_dps_);
  put_point(regs, map_.at(tm::kLock), locked_ ? 1 : 0);
  put_point(regs, map_.at(tm::kStop), stopping_ ? 1 : 0);
  put_point(regs, map_.at(tm::kAngle), angle_deg_);
  put_point(regs, map_.at(tm::kRate), rate_shown_dps_.value_or(rate_dps_));
  put_point(regs, map_.at(tm::kStatus), status_locked());
  put_point(regs, map_.at(tm::kModeActual), mode_);
}

std::uint8_t TurntableSim::check_write(const RegisterWrite& write) const {
  const auto mode = write.value_of(map_.at(tm::kModeDemand));
  if (mode && *mode != 0 && *mode != 1 && *mode != 2) return kIllegalDataValue;
  for (const char* flag : {tm::kLock, tm::kStop}) {
    const auto v = write.value_of(map_.at(flag));
    if (v && *v != 0 && *v != 1) return kIllegalDataValue;
  }
  for (const char* demand : {tm::kPositionDemand, tm::kRateDemand}) {
    const auto v = write.value_of(map_.at(demand));
    if (v && !std::isfinite(*v)) return kIllegalDataValue;
  }
  return 0;
}

void TurntableSim::on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) {
  std::lock_guard lock(mutex_);
  auto written = [&](const char* name, auto&& apply) {
    const auto& p = map_.at(name);
    if (!point_written(p, pdu_address, count)) return;
    double v = get_point(regs, p);
    if (std::isfinite(v)) apply(v);
  };
  written(tm::kPositionDemand, [&](double v) { position_demand_deg_ = wrap360(v); });
  written(tm::kRateDemand, [&](double v) { rate_demand_dps_ = v; });
  written(tm::kLock, [&](double v) { locked_ = v != 0 && rate_dps_ == 0; });
  written(tm::kStop, [&](double v) { stopping_ = v != 0; });
  written(tm::kModeDemand, [&](double v) {
    // The drive refuses to enable while the interlock or a fault is active.
    if (v >= 0 && v <= 2 && !interlock_open_ && !fault_) {
      mode_ = static_cast<int>(v);
      stopping_ = false;
    }
  });
}

}  // namespace station::sim
