// WatlowF4pChamber: the F4P map's scaling, ramp to set point and auto/manual.
#include "drivers/chamber/watlow_f4p/watlow_f4p_chamber.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "drivers/chamber/watlow_f4p/f4p_map.hpp"

namespace station::drivers {
namespace f4p = watlow_f4p;

WatlowF4pChamber::WatlowF4pChamber(std::string name, modbus::Endpoint endpoint,
                                   modbus::RegisterMap map, double response_timeout_s,
                                   std::unique_ptr<modbus::ModbusWire> wire)
    : name_(std::move(name)),
      map_(std::move(map)),
      client_(name_, endpoint,
              wire ? std::move(wire) : std::make_unique<modbus::LibmodbusWire>(endpoint),
              response_timeout_s) {
  for (const char* p :
       {f4p::kModel, f4p::kAir, f4p::kAirError, f4p::kAlarm1, f4p::kOperation,
        f4p::kControlSetpoint, f4p::kSetpoint, f4p::kSetpointLow, f4p::kSetpointHigh,
        f4p::kDecimals, f4p::kUnits, f4p::kRampMode, f4p::kRampRate, f4p::kRampScale})
    (void)map_.at(p);
}

Result<TemperatureScale> WatlowF4pChamber::scale() {
  if (scale_ && scale_connects_ == client_.connects()) return *scale_;
  auto model = raw(f4p::kModel);
  auto dec = model ? raw(f4p::kDecimals) : model;
  auto units = dec ? raw(f4p::kUnits) : dec;
  if (!units) return units.error();
  if (static_cast<int>(model.value()) != f4p::kModelF4p)
    return make_error(
        ErrorKind::protocol,
        fmt::format("{}: register 0 reads {}, not 5280 ('4P'): not an F4P", name_, model.value()));
  if (units.value() != f4p::kUnitsFahrenheit && units.value() != f4p::kUnitsCelsius)
    return make_error(
        ErrorKind::protocol,
        fmt::format("{}: units register 901 = {} (F4P: 0 deg F, 1 deg C)", name_, units.value()));
  if (dec.value() < 0 || dec.value() > 3)
    return make_error(
        ErrorKind::protocol,
        fmt::format("{}: decimal places {} (register 606) not 0..3", name_, dec.value()));
  scale_ = TemperatureScale{static_cast<int>(dec.value()),
                            static_cast<int>(units.value()) == f4p::kUnitsFahrenheit};
  scale_connects_ = client_.connects();
  return *scale_;
}

Result<double> WatlowF4pChamber::temperature_c(const char* point, const TemperatureScale& s) {
  auto v = raw(point);
  if (!v) return v.error();
  return s.c_from_raw(static_cast<std::int16_t>(v.value()));
}

Result<ChamberState> WatlowF4pChamber::read() {
  auto sc = scale();
  if (!sc) return sc.error();
  const bool full = readback_.due(client_.connects());
  auto err = raw(f4p::kAirError);
  auto alarm = err ? raw(f4p::kAlarm1) : err;
  auto air = alarm ? temperature_c(f4p::kAir, sc.value()) : alarm;
  auto sp = air ? temperature_c(f4p::kSetpoint, sc.value()) : air;
  auto csp = sp ? temperature_c(f4p::kControlSetpoint, sc.value()) : sp;
  if (csp && full) {
    auto op = raw(f4p::kOperation);
    auto mode = op ? raw(f4p::kRampMode) : op;
    auto rate = mode ? raw(f4p::kRampRate) : mode;
    auto per = rate ? raw(f4p::kRampScale) : rate;
    if (!per) csp = per.error();
    if (per) {
      auto_ = static_cast<int>(op.value()) == f4p::kAuto;
      const double r =
          sc.value().delta_to_c(sc.value().from_raw(static_cast<std::int16_t>(rate.value())));
      ramp_c_per_min_ = static_cast<int>(mode.value()) == f4p::kRampOff  ? 0.0
                        : static_cast<int>(per.value()) == f4p::kPerHour ? r / 60.0
                                                                         : r;
    }
  }
  readback_.read_done(csp.ok(), full, client_.connects());
  if (!csp) return csp.error();
  ChamberState s;
  s.alarms.sensor_break = err.value() != 0;
  s.alarms.deviation = alarm.value() != 0;
  s.air_c = s.alarms.sensor_break ? std::numeric_limits<double>::quiet_NaN() : air.value();
  s.product_c = std::numeric_limits<double>::quiet_NaN();  // one input: no product sensor
  s.setpoint_c = sp.value();
  s.ramp_c_per_min = ramp_c_per_min_;
  s.run_enabled = auto_;
  s.mode = !auto_                                      ? ChamberMode::manual
           : std::abs(csp.value() - sp.value()) > 0.05 ? ChamberMode::ramping
                                                       : ChamberMode::constant;
  return s;
}

// Ramp to set point on every change at `ramp` deg/min (F4P p. 6.7-6.8), or off for a step.
Result<void> WatlowF4pChamber::write_ramp(double ramp_c_per_min, const TemperatureScale& s) {
  if (ramp_c_per_min == 0) return client_.write(map_.at(f4p::kRampMode), f4p::kRampOff);
  // The rate register holds 1..999 in the input's decimals (p. 6.8). Per hour keeps more digits
  // of a slow rate; a rate beyond 999 per minute is written as the largest the unit takes (the
  // station's ramps are bounds, and the chamber's own capacity is lower still).
  const double per_min = s.delta_from_c(ramp_c_per_min);
  const double scale = std::pow(10.0, s.decimals);
  const bool per_hour = per_min * 60.0 * scale <= 999.0;
  const double raw_d = std::nearbyint((per_hour ? per_min * 60.0 : per_min) * scale);
  const auto raw = static_cast<std::int16_t>(std::clamp(raw_d, 1.0, 999.0));
  if (auto ok = client_.write(map_.at(f4p::kRampScale), per_hour ? f4p::kPerHour : f4p::kPerMinute);
      !ok)
    return ok;
  if (auto ok = client_.write(map_.at(f4p::kRampRate), raw); !ok) return ok;
  return client_.write(map_.at(f4p::kRampMode), f4p::kRampStartupOrChange);
}

Result<void> WatlowF4pChamber::command(const ChamberCommand& c) {
  readback_.invalidate();
  auto sc = scale();
  if (!sc) return sc.error();
  if (c.run && !*c.run)
    return make_error(ErrorKind::range,
                      fmt::format("{}: the F4P has no run output (its manual lists no event "
                                  "outputs): stop the chamber by its own switch",
                                  name_));
  if (c.ramp_c_per_min && !(*c.ramp_c_per_min >= 0 && std::isfinite(*c.ramp_c_per_min)))
    return make_error(ErrorKind::range,
                      fmt::format("{}: ramp {} C/min must be >= 0", name_, *c.ramp_c_per_min));
  std::optional<std::int16_t> sp_raw;
  if (c.setpoint_c) {
    auto lo = temperature_c(f4p::kSetpointLow, sc.value());
    auto hi = lo ? temperature_c(f4p::kSetpointHigh, sc.value()) : lo;
    if (!hi) return hi.error();
    sp_raw = sc.value().raw_from_c(*c.setpoint_c);
    if (!std::isfinite(*c.setpoint_c) || *c.setpoint_c < lo.value() - 1e-9 ||
        *c.setpoint_c > hi.value() + 1e-9 || !sp_raw)
      return make_error(ErrorKind::range,
                        fmt::format("{}: setpoint {} C outside the chamber limits [{}, {}] C",
                                    name_, *c.setpoint_c, lo.value(), hi.value()));
  }
  if (c.ramp_c_per_min) {
    if (auto ok = write_ramp(*c.ramp_c_per_min, sc.value()); !ok) return ok;
  }
  if (sp_raw) {
    if (auto ok = client_.write(map_.at(f4p::kSetpoint), *sp_raw); !ok) return ok;
  }
  if (c.run) return client_.write(map_.at(f4p::kOperation), f4p::kAuto);
  return {};
}

Result<ChamberIdentity> WatlowF4pChamber::identify() {
  auto sc = scale();
  if (!sc) return sc.error();
  auto lo = temperature_c(f4p::kSetpointLow, sc.value());
  auto hi = lo ? temperature_c(f4p::kSetpointHigh, sc.value()) : lo;
  if (!hi) return hi.error();
  ChamberIdentity id;
  id.model = "watlow_f4p";
  id.identity = "Watlow Series F4P (register 0 = 5280)";
  id.units = sc.value().fahrenheit ? "F" : "C";
  id.decimals = sc.value().decimals;
  id.setpoint_low_c = lo.value();
  id.setpoint_high_c = hi.value();
  id.notes = std::string(sc.value().fahrenheit ? "deg F converted to deg C; " : "") +
             "one input: no product temperature; run = auto mode (register 200)";
  return id;
}

}  // namespace station::drivers
