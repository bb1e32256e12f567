// The Watlow faces of the chamber model.
#include "sim_devices/faces/watlow_faces.hpp"

#include <cmath>
#include <optional>
#include <string_view>
#include <vector>

#include "sim_devices/sources/watlow_sources.hpp"

namespace station::sim {
namespace f4 = sources::f4;
namespace f4t = sources::f4t;
namespace f4p = sources::f4p;

namespace {
// The part number the simulated F4T reports: character 6 'D' = profiles, 6 alarms; character
// 11 '2' = two loops, or '7' = one loop and one cascade (CCL watlowf4t.py
// process_controller:861-921). Synthetic.
constexpr const char* kF4tPartNumber = "F4T1L2DAA0A2AAA";
constexpr const char* kF4tCascadePartNumber = "F4T1L2DAA0A7AAA";

// The rows an F4 face serves: the F4's, or an F4T's Data Map 2 (none on a cascade unit).
std::vector<sources::SourcePoint> f4_rows(const char* name, const WatlowPanel& panel) {
  if (std::string_view(name) != "watlow_f4t_map2") return sources::f4::points(panel.run_event);
  if (panel.cascade) return {};
  return sources::f4t_map2::points(panel.run_event);
}
// The F4T's rows with its floats in the word order set at the panel ([TE] 746854 p. 14; the
// rows say low word first, the default: [TE] p. 46).
std::vector<sources::SourcePoint> f4t_rows(const WatlowPanel& panel, bool rtu) {
  auto rows = f4t::points(panel.run_event, rtu);
  for (auto& r : rows)
    if (r.type == drivers::modbus::PointType::float32) r.order = panel.float_words;
  return rows;
}
// Alarm state "alarm high" shown while the deviation alarm is on (Watlow enumeration; the sources
// only name the inactive codes 88, 61, 12: an assumption of the simulator).
constexpr int kAlarmHigh = 7;
}  // namespace

double WatlowFace::raw_temp(double c) const {
  return sources::watlow_raw(c, panel_.decimals, panel_.fahrenheit);
}

double WatlowFace::c_of_raw(double raw) const {
  return sources::watlow_c_of_raw(static_cast<std::int16_t>(raw), panel_.decimals,
                                  panel_.fahrenheit);
}

double WatlowFace::unit(double c) const {
  return sources::watlow_unit(c, panel_.fahrenheit);
}
double WatlowFace::c_of_unit(double v) const {
  return sources::watlow_c(v, panel_.fahrenheit);
}

// ---------------------------------------------------------------------------------- F4
F4Face::F4Face(ChamberSim& chamber, WatlowPanel panel, int unit_id, const char* name)
    : WatlowFace(chamber, sources::register_map(name, unit_id, f4_rows(name, panel)), panel) {}

std::uint8_t F4Face::check_write(const RegisterWrite& write) const {
  for (const char* point : {f4::kRunEvent, f4::kHumidityEvent}) {
    const auto* p = map_.find(point);
    const auto ev = p != nullptr ? write.value_of(*p) : std::nullopt;
    if (ev && *ev != f4::kEventOn && *ev != f4::kEventOff) return kIllegalDataValue;
  }
  return 0;
}

void F4Face::publish(modbus_mapping_t& regs) {
  const bool broken = chamber_.air_sensor_failed();
  put(regs, f4::kAir, broken ? 32767 : raw_temp(chamber_.shown_air_c()));
  put(regs, f4::kAirError, broken ? f4::kInputOverRange : 0);
  put(regs, f4::kProduct,
      panel_.humidity ? std::nearbyint(kSimHumidityRh * std::pow(10.0, panel_.decimals))
                      : raw_temp(chamber_.product_c()));
  put(regs, f4::kProductError, 0);
  put(regs, f4::kStatus, chamber_.status() == 3 ? f4::kStatusProfilePaused : f4::kStatusConstant);
  put(regs, f4::kSetpoint, raw_temp(chamber_.setpoint_c()));
  put(regs, f4::kSetpointLow, raw_temp(chamber_.config().setpoint_low_c));
  put(regs, f4::kSetpointHigh, raw_temp(chamber_.config().setpoint_high_c));
  put(regs, f4::kDecimals, panel_.decimals);
  put(regs, f4::kDecimals2, panel_.decimals);
  put(regs, f4::kUnits, panel_.fahrenheit ? f4::kUnitsFahrenheit : f4::kUnitsCelsius);
  put(regs, f4::kRunEvent, chamber_.run() ? f4::kEventOn : f4::kEventOff);
  put(regs, f4::kInput1Units, f4::kInputTemperature);
  put(regs, f4::kInput2Units, panel_.humidity ? f4::kInputHumidity : f4::kInputTemperature);
  put(regs, f4::kHumidityEvent, humidity_on_ ? f4::kEventOn : f4::kEventOff);
}

void F4Face::on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) {
  const auto& sp = map_.at(f4::kSetpoint);
  if (point_written(sp, pdu_address, count)) chamber_.set_setpoint_c(c_of_raw(get_point(regs, sp)));
  const auto& ev = map_.at(f4::kRunEvent);
  if (point_written(ev, pdu_address, count)) chamber_.set_run(get_point(regs, ev) == f4::kEventOn);
  if (const auto* h = map_.find(f4::kHumidityEvent); h && point_written(*h, pdu_address, count))
    humidity_on_ = get_point(regs, *h) == f4::kEventOn;
}

// --------------------------------------------------------------------------------- F4T
F4tFace::F4tFace(ChamberSim& chamber, WatlowPanel panel, int unit_id, bool rtu)
    : WatlowFace(chamber, sources::register_map("watlow_f4t", unit_id, f4t_rows(panel, rtu)),
                 panel) {}

std::uint8_t F4tFace::check_write(const RegisterWrite& write) const {
  for (const char* point : {f4t::kRunEvent, f4t::kHumidityEvent}) {
    const auto* p = map_.find(point);
    const auto ev = p != nullptr ? write.value_of(*p) : std::nullopt;
    if (ev && *ev != f4t::kOn && *ev != f4t::kOff) return kIllegalDataValue;
  }
  const auto action = write.value_of(map_.at(f4t::kRampAction));
  if (action && *action != f4t::kOff && *action != f4t::kRampSetpoint && *action != f4t::kStartup &&
      *action != f4t::kRampBoth)
    return kIllegalDataValue;
  const auto scale = write.value_of(map_.at(f4t::kRampScale));
  if (scale && *scale != f4t::kMinutes && *scale != f4t::kHours) return kIllegalDataValue;
  const auto rate = write.value_of(map_.at(f4t::kRampRate));
  if (rate && !(std::isfinite(*rate) && *rate >= 0)) return kIllegalDataValue;
  const auto sp = write.value_of(map_.at(f4t::kSetpoint));
  if (sp && !std::isfinite(*sp)) return kIllegalDataValue;
  return 0;
}

void F4tFace::publish(modbus_mapping_t& regs) {
  put(regs, f4t::kAir, chamber_.air_sensor_failed() ? NAN : unit(chamber_.shown_air_c()));
  put(regs, f4t::kProduct, panel_.humidity ? kSimHumidityRh : unit(chamber_.product_c()));
  put(regs, f4t::kLoop1Kind, f4t::kAbsoluteTemperature);
  put(regs, f4t::kLoop2Kind, panel_.humidity ? f4t::kHumidity : f4t::kAbsoluteTemperature);
  put(regs, f4t::kHumidityEvent, humidity_on_ ? f4t::kOn : f4t::kOff);
  put(regs, f4t::kSetpoint, unit(chamber_.setpoint_c()));
  put(regs, f4t::kWorkingSetpoint, unit(chamber_.effective_setpoint_c()));
  put(regs, f4t::kSetpointLow, unit(chamber_.config().setpoint_low_c));
  put(regs, f4t::kSetpointHigh, unit(chamber_.config().setpoint_high_c));
  put(regs, f4t::kLoopMode, chamber_.run() ? f4t::kAuto : f4t::kOff);
  put(regs, f4t::kRampAction, ramp_action_);
  put(regs, f4t::kRampScale, ramp_scale_);
  put(regs, f4t::kRampRate, ramp_rate_);
  put(regs, f4t::kProfileState, chamber_.status() == 3 ? f4t::kProfilePaused : 0);
  // Alarm 1 watches the air loop: with its input broken its state is "error" (A, DEVICES.md).
  put(regs, f4t::kAlarm1,
      chamber_.air_sensor_failed()    ? f4t::kAlarmError
      : (chamber_.alarms() & 1u) != 0 ? kAlarmHigh
                                      : f4t::kAlarmNone);
  put(regs, f4t::kRunEvent, chamber_.run() ? f4t::kOn : f4t::kOff);
  put(regs, f4t::kUnits, panel_.fahrenheit ? f4t::kFahrenheit : f4t::kCelsius);
  for (int i = 0; i < f4t::kPartNumberRegisters; ++i)
    put(regs, f4t::part_number_point(i).c_str(),
        (panel_.cascade ? kF4tCascadePartNumber : kF4tPartNumber)[i]);
}

void F4tFace::on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) {
  auto written = [&](const char* name) { return point_written(map_.at(name), pdu_address, count); };
  auto value = [&](const char* name) { return get_point(regs, map_.at(name)); };
  if (written(f4t::kRampAction)) ramp_action_ = static_cast<int>(value(f4t::kRampAction));
  if (written(f4t::kRampScale)) ramp_scale_ = static_cast<int>(value(f4t::kRampScale));
  if (written(f4t::kRampRate)) ramp_rate_ = value(f4t::kRampRate);
  if (written(f4t::kRampAction) || written(f4t::kRampScale) || written(f4t::kRampRate)) {
    const double per_min = ramp_scale_ == f4t::kHours ? ramp_rate_ / 60.0 : ramp_rate_;
    chamber_.set_ramp_c_per_min(
        ramp_action_ == f4t::kOff ? 0.0 : sources::watlow_c_delta(per_min, panel_.fahrenheit));
  }
  if (written(f4t::kSetpoint)) chamber_.set_setpoint_c(c_of_unit(value(f4t::kSetpoint)));
  if (written(f4t::kRunEvent)) chamber_.set_run(value(f4t::kRunEvent) == f4t::kOn);
  if (const auto* h = map_.find(f4t::kHumidityEvent); h && point_written(*h, pdu_address, count))
    humidity_on_ = get_point(regs, *h) == f4t::kOn;
}

// --------------------------------------------------------------------------------- F4P
F4pFace::F4pFace(ChamberSim& chamber, WatlowPanel panel, int unit_id)
    : WatlowFace(chamber, sources::register_map("watlow_f4p", unit_id, f4p::points()), panel) {}

std::uint8_t F4pFace::check_write(const RegisterWrite& write) const {
  const auto op = write.value_of(map_.at(f4p::kOperation));
  if (op && *op != f4p::kAuto && *op != f4p::kManual) return kIllegalDataValue;
  const auto mode = write.value_of(map_.at(f4p::kRampMode));
  if (mode && (*mode < f4p::kRampOff || *mode > f4p::kRampMax)) return kIllegalDataValue;
  const auto rate = write.value_of(map_.at(f4p::kRampRate));
  if (rate && (*rate < f4p::kRampRateMin || *rate > f4p::kRampRateMax)) return kIllegalDataValue;
  const auto scale = write.value_of(map_.at(f4p::kRampScale));
  if (scale && *scale != f4p::kPerMinute && *scale != f4p::kPerHour) return kIllegalDataValue;
  return 0;
}

void F4pFace::publish(modbus_mapping_t& regs) {
  const bool broken = chamber_.air_sensor_failed();
  put(regs, f4p::kModel, f4p::kModelF4p);
  put(regs, f4p::kAir, broken ? 32767 : raw_temp(chamber_.shown_air_c()));
  put(regs, f4p::kAirError, broken ? f4p::kInputOverRange : 0);
  put(regs, f4p::kAlarm1, (chamber_.alarms() & 1u) != 0 ? 1 : 0);
  put(regs, f4p::kOperation, chamber_.run() ? f4p::kAuto : f4p::kManual);
  put(regs, f4p::kControlSetpoint, raw_temp(chamber_.effective_setpoint_c()));
  put(regs, f4p::kSetpoint, raw_temp(chamber_.setpoint_c()));
  put(regs, f4p::kSetpointLow, raw_temp(chamber_.config().setpoint_low_c));
  put(regs, f4p::kSetpointHigh, raw_temp(chamber_.config().setpoint_high_c));
  put(regs, f4p::kDecimals, panel_.decimals);
  put(regs, f4p::kUnits, panel_.fahrenheit ? f4p::kUnitsFahrenheit : f4p::kUnitsCelsius);
  put(regs, f4p::kRampMode, ramp_mode_);
  put(regs, f4p::kRampRate, ramp_rate_raw_);
  put(regs, f4p::kRampScale, ramp_scale_);
}

void F4pFace::on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) {
  auto written = [&](const char* name) { return point_written(map_.at(name), pdu_address, count); };
  auto value = [&](const char* name) { return get_point(regs, map_.at(name)); };
  if (written(f4p::kRampMode)) ramp_mode_ = static_cast<int>(value(f4p::kRampMode));
  if (written(f4p::kRampRate)) ramp_rate_raw_ = value(f4p::kRampRate);
  if (written(f4p::kRampScale)) ramp_scale_ = static_cast<int>(value(f4p::kRampScale));
  if (written(f4p::kRampMode) || written(f4p::kRampRate) || written(f4p::kRampScale)) {
    // The rate carries the input's implied decimals (p. 6.8), a difference: no deg F offset.
    const double per_scale =
        static_cast<std::int16_t>(ramp_rate_raw_) * std::pow(10.0, -panel_.decimals);
    const double rate = sources::watlow_c_delta(per_scale, panel_.fahrenheit);
    chamber_.set_ramp_c_per_min(ramp_mode_ == f4p::kRampOff    ? 0.0
                                : ramp_scale_ == f4p::kPerHour ? rate / 60.0
                                                               : rate);
  }
  if (written(f4p::kSetpoint)) chamber_.set_setpoint_c(c_of_raw(value(f4p::kSetpoint)));
  if (written(f4p::kOperation)) chamber_.set_run(value(f4p::kOperation) == f4p::kAuto);
}

}  // namespace station::sim
