// WatlowF4tChamber: Data Map 1 points, Watlow enumerations and the controller's ramp.
#include "drivers/chamber/watlow_f4t/watlow_f4t_chamber.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "drivers/chamber/float_word_order.hpp"
#include "drivers/chamber/watlow_f4t/f4t_map.hpp"
#include "drivers/modbus/map_overrides.hpp"

namespace station::drivers {
namespace f4t = watlow_f4t;

namespace {

bool alarm_active(int state) {
  return std::find(f4t::kAlarmInactive.begin(), f4t::kAlarmInactive.end(), state) ==
         f4t::kAlarmInactive.end();
}

ChamberMode mode_of(int loop_mode, int profile_state, bool ramping) {
  if (profile_state == f4t::kProfileRunning) return ChamberMode::profile;
  if (profile_state == f4t::kProfilePaused) return ChamberMode::hold;
  if (loop_mode == f4t::kOff) return ChamberMode::off;
  if (loop_mode == f4t::kManual) return ChamberMode::manual;
  return ramping ? ChamberMode::ramping : ChamberMode::constant;
}

}  // namespace

WatlowF4tChamber::WatlowF4tChamber(std::string name, modbus::Endpoint endpoint,
                                   modbus::RegisterMap map, double response_timeout_s,
                                   std::unique_ptr<modbus::ModbusWire> wire, WatlowInputs inputs)
    : name_(std::move(name)),
      map_(std::move(map)),
      client_(name_, endpoint,
              wire ? std::move(wire) : std::make_unique<modbus::LibmodbusWire>(endpoint),
              response_timeout_s),
      inputs_(inputs) {
  for (const char* p :
       {f4t::kAir, f4t::kProduct, f4t::kSetpoint, f4t::kWorkingSetpoint, f4t::kSetpointLow,
        f4t::kSetpointHigh, f4t::kLoopMode, f4t::kRampAction, f4t::kRampScale, f4t::kRampRate,
        f4t::kProfileState, f4t::kAlarm1, f4t::kRunEvent, f4t::kUnits})
    (void)map_.at(p);
}

Result<double> WatlowF4tChamber::value(const char* point) {
  return client_.read(map_.at(point));
}

// The display unit (CCL __profile_units: 15 deg C, 30 deg F), read once per connection; any
// other value is refused rather than guessed.
Result<TemperatureScale> WatlowF4tChamber::scale() {
  if (scale_ && scale_connects_ == client_.connects()) return *scale_;
  auto u = value(f4t::kUnits);
  if (!u) return units_error(u.error());
  const int units = static_cast<int>(u.value());
  if (units != f4t::kCelsius && units != f4t::kFahrenheit)
    return make_error(ErrorKind::protocol,
                      fmt::format("{}: units register {} = {} (F4T: 15 deg C, 30 deg F): refusing "
                                  "to read temperatures",
                                  name_, map_.at(f4t::kUnits).address, units));
  if (auto c = check_controller(); !c) return c.error();
  scale_ = TemperatureScale{-1, units == f4t::kFahrenheit};
  scale_connects_ = client_.connects();
  return *scale_;
}

// A unit set to the other word order is refused, never read as 2.4e-41 (float_word_order.hpp).
Result<double> WatlowF4tChamber::temperature_c(const char* point, const TemperatureScale& s) {
  auto v = value(point);
  if (!v) return v.error();
  if (auto wrong = word_order_mismatch(map_.at(point), v.value()))
    return make_error(ErrorKind::protocol, name_ + ": " + *wrong);
  return s.to_c(v.value());
}

// The points read with the command registers: mode, profile, ramp, run, product.
Result<void> WatlowF4tChamber::read_commands(const TemperatureScale& s) {
  auto mode = value(f4t::kLoopMode);
  auto profile = mode ? value(f4t::kProfileState) : mode;
  auto action = profile ? value(f4t::kRampAction) : profile;
  auto rate = action ? value(f4t::kRampRate) : action;
  auto scale = rate ? value(f4t::kRampScale) : rate;
  auto run = scale ? value(f4t::kRunEvent) : scale;
  if (!run) return run.error();
  const bool ramp_on = static_cast<int>(action.value()) != f4t::kOff;
  const double per = static_cast<int>(scale.value()) == f4t::kHours ? 1.0 / 60.0 : 1.0;
  ramp_c_per_min_ = ramp_on ? s.delta_to_c(rate.value()) * per : 0.0;
  run_enabled_ = static_cast<int>(run.value()) == f4t::kOn;
  mode_ = mode_of(static_cast<int>(mode.value()), static_cast<int>(profile.value()), false);
  if (inputs_.product_input != 0) {
    auto product = temperature_c(f4t::kProduct, s);
    if (!product) return product.error();
    product_c_ = product.value();
  }
  return {};  // a read never writes: humidity control is switched off by command() only
}

Result<ChamberState> WatlowF4tChamber::read() {
  auto sc = scale();
  if (!sc) return sc.error();
  const bool full = readback_.due(client_.connects());
  auto alarm = value(f4t::kAlarm1);
  auto air = alarm ? temperature_c(f4t::kAir, sc.value()) : alarm;
  auto sp = air ? temperature_c(f4t::kSetpoint, sc.value()) : air;
  auto wsp = sp ? temperature_c(f4t::kWorkingSetpoint, sc.value()) : sp;
  Result<void> cmds = wsp ? (full ? read_commands(sc.value()) : Result<void>{}) : wsp.error();
  readback_.read_done(cmds.ok(), full, client_.connects());
  if (!cmds) return cmds.error();
  ChamberState s;
  // A broken air sensor: the loop's PV reads NaN, or alarm 1 (sourced from it) is in error.
  const int alarm_state = static_cast<int>(alarm.value());
  s.alarms.sensor_break = !std::isfinite(air.value()) || alarm_state == f4t::kAlarmError;
  s.alarms.deviation = alarm_state != f4t::kAlarmError && alarm_active(alarm_state);
  s.air_c = s.alarms.sensor_break ? std::numeric_limits<double>::quiet_NaN() : air.value();
  s.setpoint_c = sp.value();
  s.product_c = inputs_.product_input != 0 ? product_c_ : std::numeric_limits<double>::quiet_NaN();
  s.ramp_c_per_min = ramp_c_per_min_;
  s.run_enabled = run_enabled_;
  // The working setpoint still moving towards the target: the controller ramps.
  s.mode = mode_ == ChamberMode::constant && std::abs(wsp.value() - sp.value()) > 0.05
               ? ChamberMode::ramping
               : mode_;
  return s;
}

Result<void> WatlowF4tChamber::command(const ChamberCommand& c) {
  readback_.invalidate();
  auto sc = scale();
  if (!sc) return sc.error();
  if (c.ramp_c_per_min && !(*c.ramp_c_per_min >= 0 && std::isfinite(*c.ramp_c_per_min)))
    return make_error(ErrorKind::range,
                      fmt::format("{}: ramp {} C/min must be >= 0", name_, *c.ramp_c_per_min));
  if (c.setpoint_c) {
    auto lo = temperature_c(f4t::kSetpointLow, sc.value());
    auto hi = lo ? temperature_c(f4t::kSetpointHigh, sc.value()) : lo;
    if (!hi) return hi.error();
    if (!std::isfinite(lo.value()) || !std::isfinite(hi.value()) || lo.value() > hi.value())
      return make_error(ErrorKind::protocol,
                        fmt::format("{}: setpoint limits read [{}, {}] C: not a range; nothing "
                                    "written",
                                    name_, lo.value(), hi.value()));
    if (!std::isfinite(*c.setpoint_c) || *c.setpoint_c < lo.value() - 1e-6 ||
        *c.setpoint_c > hi.value() + 1e-6)
      return make_error(ErrorKind::range,
                        fmt::format("{}: setpoint {} C outside the chamber limits [{}, {}] C",
                                    name_, *c.setpoint_c, lo.value(), hi.value()));
  }
  if (c.ramp_c_per_min) {
    const bool step = *c.ramp_c_per_min == 0;
    if (!step) {
      if (auto ok = client_.write(map_.at(f4t::kRampScale), f4t::kMinutes); !ok) return ok;
      const double rate = sc.value().delta_from_c(*c.ramp_c_per_min);
      if (auto ok = client_.write(map_.at(f4t::kRampRate), rate); !ok) return ok;
    }
    const int action = step ? f4t::kOff : f4t::kRampSetpoint;
    if (auto ok = client_.write(map_.at(f4t::kRampAction), action); !ok) return ok;
  }
  if (c.setpoint_c) {
    const double sp = sc.value().from_c(*c.setpoint_c);
    if (auto ok = client_.write(map_.at(f4t::kSetpoint), sp); !ok) return ok;
  }
  if (c.run) {
    if (*c.run && humidity_chamber_) {
      if (auto off = humidity_off(); !off) return off;
    }
    const int v = *c.run ? f4t::kOn : f4t::kOff;
    if (auto ok = client_.write(map_.at(f4t::kRunEvent), v); !ok) return ok;
  }
  return {};
}

Result<ChamberIdentity> WatlowF4tChamber::identify() {
  auto sc = scale();
  if (!sc) return sc.error();
  const std::string& part = part_.text;  // read with the scale
  auto lo = temperature_c(f4t::kSetpointLow, sc.value());
  auto hi = lo ? temperature_c(f4t::kSetpointHigh, sc.value()) : lo;
  if (!hi) return hi.error();
  ChamberIdentity id;
  id.model = "watlow_f4t";
  id.identity = part.empty() ? "F4T (part number empty)" : "F4T part number " + part;
  id.units = sc.value().fahrenheit ? "F" : "C";
  id.setpoint_low_c = lo.value();
  id.setpoint_high_c = hi.value();
  id.notes = fmt::format("{}run = event output at register {}; ramps by the controller; {}; {}",
                         sc.value().fahrenheit ? "deg F converted to deg C; " : "",
                         map_.at(f4t::kRunEvent).address, input_notes(), link_notes());
  return id;
}

// The word order and the units register in use (docs/DEVICES.md, "what to check first").
std::string WatlowF4tChamber::link_notes() const {
  const modbus::Point& air = map_.at(f4t::kAir);
  const modbus::Point& units = map_.at(f4t::kUnits);
  return fmt::format("floats {} (word_order = \"{}\"); units register {} ({})",
                     air.order == modbus::WordOrder::cdab ? "low word first" : "high word first",
                     modbus::float_word_order_name(air.order), units.address,
                     units.address == f4t::kUnitsRtu ? "the serial port's" : "the TCP port's");
}

// A units register the unit does not serve: an F4T behind a TCP-to-RTU gateway serves its serial
// port's (14080, CCL __profile_units:1002), which `gateway = true` selects (docs/DEVICES.md).
Error WatlowF4tChamber::units_error(Error e) const {
  if (e.kind == ErrorKind::exception && client_.unit_answered() &&
      map_.at(f4t::kUnits).address == f4t::kUnitsTcp)
    e.message += fmt::format(
        "; an F4T behind a TCP-to-RTU gateway serves its serial port's units at register {}: set "
        "[chamber] gateway = true",
        f4t::kUnitsRtu);
  return e;
}

// The controller behind the map (CCL process_controller:861-921): a cascade unit serves its
// loops at other registers (TestEquity F4T manual, cascade edition p. 15) and is refused, as is a
// product loop the unit has not; with the profile option the air and product loops' kinds are
// read (CCL __profile_units:991-1007), so a %RH loop is never read as a temperature.
Result<void> WatlowF4tChamber::check_controller() {
  auto words = client_.read_registers(modbus::FunctionCode::holding, map_.at(f4t::kUnits).unit_id,
                                      f4t::kPartNumberAddress, f4t::kPartNumberRegisters);
  if (!words) return words.error();
  part_ = f4t::parse_part_number(words.value());
  humidity_chamber_ = false;
  const auto refuse = [&](const std::string& why) {
    return make_error(ErrorKind::protocol,
                      fmt::format("{}: part number '{}': {}", name_, part_.text, why));
  };
  if (part_.cascades > 0)
    return refuse(
        fmt::format("{} cascade loop(s) (character 12, CCL process_controller:884-916): "
                    "a cascade F4T serves its loops at other registers; not supported",
                    part_.cascades));
  if (inputs_.product_input > part_.loops)
    return refuse(fmt::format("product_input = {} but the controller has {} loop(s)",
                              inputs_.product_input, part_.loops));
  if (!part_.profiles && inputs_.product_input != 0)
    return refuse(
        fmt::format("product_input = {}: without the profile option (character 7) the "
                    "loops' kinds are not served, so a %RH loop cannot be told from a "
                    "temperature; not read",
                    inputs_.product_input));
  if (!part_.profiles) return {};  // no profile option: the kinds are not served
  const auto kind = [&](const char* p) -> Result<int> {
    auto v = value(p);
    if (!v) return v.error();
    return static_cast<int>(v.value());
  };
  const auto is_temperature = [](int k) {
    // CCL __profile_units:1000 reads these three as temperatures.
    return k == f4t::kAbsoluteTemperature || k == f4t::kRelativeTemperature ||
           k == f4t::kNotSourced;
  };
  auto air = kind(f4t::kAirKind);
  if (!air) return air.error();
  if (!is_temperature(air.value()))
    return refuse(fmt::format("the air loop reads kind {} (register {}): not a temperature",
                              air.value(), map_.at(f4t::kAirKind).address));
  if (part_.loops < 2 && inputs_.product_input == 0) return {};
  auto product = kind(f4t::kProductKind);
  if (!product) return product.error();
  humidity_chamber_ = product.value() == f4t::kHumidity;
  if (inputs_.product_input != 0 && !is_temperature(product.value()))
    return refuse(fmt::format(
        "loop {} reads {} (register {} = {}): product_input names no "
        "temperature; set product_input = 0",
        inputs_.product_input, product.value() == f4t::kHumidity ? "%RH" : "no temperature",
        map_.at(f4t::kProductKind).address, product.value()));
  return {};
}

// Humidity control off: the humidity event output (TestEquity wiring, f4t_map.hpp), if mapped.
Result<void> WatlowF4tChamber::humidity_off() {
  const auto* ev = map_.find(f4t::kHumidityEvent);
  if (ev == nullptr) return {};
  auto now = client_.read(*ev);
  if (!now) return now.error();
  if (static_cast<int>(now.value()) == f4t::kOff) return {};
  return client_.write(*ev, f4t::kOff);
}

std::string WatlowF4tChamber::input_notes() const {
  const auto* hum = map_.find(f4t::kHumidityEvent);
  std::string n = inputs_.product_input == 0
                      ? "product: none configured (product_input = 0)"
                      : fmt::format("product: loop {} (register {})", inputs_.product_input,
                                    map_.at(f4t::kProduct).address);
  if (!part_.profiles)
    n += "; loop kinds not served (no profile option): no product loop, humidity not managed";
  if (humidity_chamber_)
    n += hum != nullptr ? fmt::format(
                              "; humidity chamber (loop 2 reads %RH): humidity control "
                              "(event output at register {}) switched off when the "
                              "station starts the chamber",
                              hum->address)
                        : std::string(
                              "; humidity chamber (loop 2 reads %RH): no humidity event "
                              "configured, humidity control NOT switched off");
  return n;
}

}  // namespace station::drivers
