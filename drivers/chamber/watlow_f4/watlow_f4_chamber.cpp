// WatlowF4Chamber: scaling read from the controller, status and event semantics of the F4 map.
#include "drivers/chamber/watlow_f4/watlow_f4_chamber.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "drivers/chamber/watlow_f4/f4_map.hpp"

namespace station::drivers {
namespace f4 = watlow_f4;

namespace {

Result<ChamberMode> mode_of_status(int status, bool run, const std::string& name) {
  switch (status) {
    case f4::kConstant0:
    case f4::kConstant1:
      return run ? ChamberMode::constant : ChamberMode::off;
    case f4::kProfileRunning:
      return ChamberMode::profile;
    case f4::kProfilePaused:
      return ChamberMode::hold;
    default:
      return make_error(ErrorKind::protocol,
                        fmt::format("{}: status register 200 = {} (F4: 0..3)", name, status));
  }
}

}  // namespace

WatlowF4Chamber::WatlowF4Chamber(std::string name, std::string model, modbus::Endpoint endpoint,
                                 modbus::RegisterMap map, double response_timeout_s,
                                 std::unique_ptr<modbus::ModbusWire> wire)
    : name_(std::move(name)),
      model_(std::move(model)),
      map_(std::move(map)),
      client_(name_, endpoint,
              wire ? std::move(wire) : std::make_unique<modbus::LibmodbusWire>(endpoint),
              response_timeout_s) {
  for (const char* p :
       {f4::kAir, f4::kAirError, f4::kProduct, f4::kStatus, f4::kSetpoint, f4::kSetpointLow,
        f4::kSetpointHigh, f4::kDecimals, f4::kDecimals2, f4::kUnits, f4::kRunEvent})
    (void)map_.at(p);  // throws naming the missing point
}

// Decimal places (606/616) and units (901), read once per connection: a controller reconfigured
// at the panel is read afresh after the next reconnect. Decimals outside 0..3 are refused.
Result<TemperatureScale> WatlowF4Chamber::scale() {
  if (scale_ && scale_connects_ == client_.connects()) return *scale_;
  std::vector<double> v;
  for (const char* p : {f4::kDecimals, f4::kDecimals2, f4::kUnits}) {
    auto r = client_.read(map_.at(p));
    if (!r) return r.error();
    v.push_back(r.value());
  }
  for (double d : {v[0], v[1]})
    if (d < 0 || d > 3)
      return make_error(ErrorKind::protocol,
                        fmt::format("{}: decimal places {} (registers 606/616) not 0..3: refusing "
                                    "to scale temperatures",
                                    name_, d));
  const bool f = static_cast<int>(v[2]) == f4::kUnitsFahrenheit;
  scale_ = TemperatureScale{static_cast<int>(v[0]), f};
  product_scale_ = TemperatureScale{static_cast<int>(v[1]), f};
  scale_connects_ = client_.connects();
  return *scale_;
}

Result<double> WatlowF4Chamber::temperature_c(const char* point, const TemperatureScale& s) {
  auto raw = client_.read(map_.at(point));
  if (!raw) return raw.error();
  return s.c_from_raw(static_cast<std::int16_t>(raw.value()));
}

Result<ChamberState> WatlowF4Chamber::read() {
  auto sc = scale();
  if (!sc) return sc.error();
  const bool full = readback_.due(client_.connects());
  ChamberState s;
  auto err = client_.read(map_.at(f4::kAirError));
  auto air = err ? temperature_c(f4::kAir, sc.value()) : Result<double>(err.error());
  auto sp = air ? temperature_c(f4::kSetpoint, sc.value()) : air;
  if (!sp) {
    readback_.read_done(false, full, client_.connects());
    return sp.error();
  }
  s.alarms.sensor_break = err.value() != 0;  // F4P p. 9.6: 0 none, 1..6 an input error
  s.air_c = s.alarms.sensor_break ? std::numeric_limits<double>::quiet_NaN() : air.value();
  s.setpoint_c = sp.value();
  if (full) {
    auto status = client_.read(map_.at(f4::kStatus));
    auto run = status ? client_.read(map_.at(f4::kRunEvent)) : status;
    auto perr = run ? client_.read(map_.at(f4::kProductError)) : run;
    auto product = perr ? temperature_c(f4::kProduct, *product_scale_) : perr;
    auto mode = product ? mode_of_status(static_cast<int>(status.value()),
                                         run.value() == f4::kEventOn, name_)
                        : Result<ChamberMode>(product.error());
    if (!mode) {
      readback_.read_done(false, full, client_.connects());
      return mode.error();
    }
    run_enabled_ = run.value() == f4::kEventOn;
    mode_ = mode.value();
    product_c_ = perr.value() != 0 ? std::numeric_limits<double>::quiet_NaN() : product.value();
  }
  readback_.read_done(true, full, client_.connects());
  s.product_c = product_c_;
  s.mode = mode_;
  s.run_enabled = run_enabled_;
  s.ramp_c_per_min = 0;  // no constant-mode ramp on an F4
  return s;
}

Result<void> WatlowF4Chamber::command(const ChamberCommand& c) {
  readback_.invalidate();
  auto sc = scale();
  if (!sc) return sc.error();
  if (c.setpoint_c) {
    auto lo = temperature_c(f4::kSetpointLow, sc.value());
    if (!lo) return lo.error();
    auto hi = temperature_c(f4::kSetpointHigh, sc.value());
    if (!hi) return hi.error();
    const auto raw = sc.value().raw_from_c(*c.setpoint_c);
    if (!std::isfinite(*c.setpoint_c) || *c.setpoint_c < lo.value() - 1e-9 ||
        *c.setpoint_c > hi.value() + 1e-9 || !raw)
      return make_error(ErrorKind::range,
                        fmt::format("{}: setpoint {} C outside the chamber limits [{}, {}] C",
                                    name_, *c.setpoint_c, lo.value(), hi.value()));
    if (auto ok = client_.write(map_.at(f4::kSetpoint), *raw); !ok) return ok;
  }
  if (c.run) {
    const int v = *c.run ? f4::kEventOn : f4::kEventOff;
    if (auto ok = client_.write(map_.at(f4::kRunEvent), v); !ok) return ok;
  }
  return {};
}

Result<ChamberIdentity> WatlowF4Chamber::identify() {
  auto sc = scale();
  if (!sc) return sc.error();
  auto lo = temperature_c(f4::kSetpointLow, sc.value());
  if (!lo) return lo.error();
  auto hi = temperature_c(f4::kSetpointHigh, sc.value());
  if (!hi) return hi.error();
  ChamberIdentity id;
  id.model = model_;
  id.identity = "Watlow F4 map (no identity register in the sources)";
  id.units = sc.value().fahrenheit ? "F" : "C";
  id.decimals = sc.value().decimals;
  id.setpoint_low_c = lo.value();
  id.setpoint_high_c = hi.value();
  id.notes = fmt::format(
      "{}run = event output at register {}; no constant-mode ramp: the station "
      "ramps the setpoint",
      sc.value().fahrenheit ? "deg F converted to deg C; " : "", map_.at(f4::kRunEvent).address);
  return id;
}

}  // namespace station::drivers
