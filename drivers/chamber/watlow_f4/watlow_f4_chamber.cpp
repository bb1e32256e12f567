// WatlowF4Chamber: scaling and input kinds read from the controller, status and event semantics
// of the F4 map (and of the smaller Data Map 2 of an F4T).
#include "drivers/chamber/watlow_f4/watlow_f4_chamber.hpp"

#include <fmt/format.h>
#include <modbus.h>

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

const char* kind_name(int kind) {
  switch (kind) {
    case f4::kTemperature:
      return "a temperature";
    case f4::kHumidity:
      return "%RH";
    case f4::kPressure:
      return "PSI";
    case f4::kNoInput:
      return "nothing (no input)";
    default:
      return "an unknown quantity";
  }
}

}  // namespace

WatlowF4Chamber::WatlowF4Chamber(std::string name, std::string model, modbus::Endpoint endpoint,
                                 modbus::RegisterMap map, double response_timeout_s,
                                 std::unique_ptr<modbus::ModbusWire> wire, WatlowInputs inputs)
    : name_(std::move(name)),
      model_(std::move(model)),
      map_(std::move(map)),
      client_(name_, endpoint,
              wire ? std::move(wire) : std::make_unique<modbus::LibmodbusWire>(endpoint),
              response_timeout_s),
      inputs_(inputs) {
  // Every map (F4 and Data Map 2) has these; status, limits and input units only the F4's.
  for (const char* p : {f4::kAir, f4::kAirError, f4::kProduct, f4::kProductError, f4::kSetpoint,
                        f4::kDecimals, f4::kDecimals2, f4::kUnits, f4::kRunEvent})
    (void)map_.at(p);  // throws naming the missing point
}

// What inputs 1 and 2 measure (608/618, CCL get_loop_units:392-397), where the map has them:
// the air must be a temperature, so must a configured product input; %RH on input 2 makes this a
// humidity chamber.
Result<void> WatlowF4Chamber::read_input_kinds() {
  humidity_chamber_ = false;
  const auto kind = [&](const char* point) -> Result<int> {
    auto v = client_.read(map_.at(point));
    if (!v) return v.error();
    return static_cast<int>(v.value());
  };
  if (map_.find(f4::kInput1Units) != nullptr) {
    auto k1 = kind(f4::kInput1Units);
    if (!k1) return k1.error();
    if (k1.value() != f4::kTemperature)
      return make_error(ErrorKind::protocol,
                        fmt::format("{}: input 1 measures {} (register 608 = {}): the air input "
                                    "must be a temperature",
                                    name_, kind_name(k1.value()), k1.value()));
  }
  if (map_.find(f4::kInput2Units) == nullptr) {
    // Data Map 2: input 2 (104) is the chamber humidity by its documents (TestEquity F4T manual
    // p. 47, 101H p. 61); its humidity event (if configured) is kept off like any humidity
    // chamber's.
    humidity_chamber_ = true;
    return {};
  }
  auto k2 = kind(f4::kInput2Units);
  if (!k2) return k2.error();
  humidity_chamber_ = k2.value() == f4::kHumidity;
  if (inputs_.product_input == 2 && k2.value() != f4::kTemperature)
    return make_error(ErrorKind::protocol,
                      fmt::format("{}: input 2 measures {} (register 618 = {}): product_input = 2 "
                                  "names no temperature; set product_input = 0",
                                  name_, kind_name(k2.value()), k2.value()));
  return {};
}

// Decimal places (606/616), units (901) and the inputs' kinds, read once per connection: a
// controller reconfigured at the panel is read afresh after the next reconnect. Decimals outside
// 0..3 are refused.
Result<TemperatureScale> WatlowF4Chamber::scale() {
  if (scale_ && scale_connects_ == client_.connects()) return *scale_;
  std::vector<double> v;
  for (const char* p : {f4::kDecimals, f4::kDecimals2, f4::kUnits}) {
    auto r = client_.read(map_.at(p));
    // Only the unit's own "illegal data address" (02) says the map is not served; a busy or
    // failing unit (04, 06) or a gateway's 0x0B keeps its own message.
    if (!r && r.error().kind == ErrorKind::exception && map_.find(f4::kStatus) == nullptr &&
        r.error().message.find(modbus_strerror(EMBXILADD)) != std::string::npos)
      return make_error(ErrorKind::exception,
                        fmt::format("{} — the unit serves no Data Map 2 here: an F4T with cascade "
                                    "control has none (TestEquity F4T manual p. 47) and is not "
                                    "supported",
                                    r.error().message));
    if (!r) return r.error();
    v.push_back(r.value());
  }
  for (double d : {v[0], v[1]})
    if (d < 0 || d > 3)
      return make_error(ErrorKind::protocol,
                        fmt::format("{}: decimal places {} (registers 606/616) not 0..3: refusing "
                                    "to scale temperatures",
                                    name_, d));
  if (auto k = read_input_kinds(); !k) return k.error();
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

// Status (where the map serves it), run event, the configured product input.
Result<void> WatlowF4Chamber::read_commands() {
  auto run = client_.read(map_.at(f4::kRunEvent));
  if (!run) return run.error();
  run_enabled_ = run.value() == f4::kEventOn;
  if (map_.find(f4::kStatus) != nullptr) {
    auto status = client_.read(map_.at(f4::kStatus));
    auto mode = status ? mode_of_status(static_cast<int>(status.value()), run_enabled_, name_)
                       : Result<ChamberMode>(status.error());
    if (!mode) return mode.error();
    mode_ = mode.value();
  } else {
    mode_ = run_enabled_ ? ChamberMode::constant : ChamberMode::off;  // Data Map 2: no status
  }
  if (inputs_.product_input == 2) {
    auto perr = client_.read(map_.at(f4::kProductError));
    auto product = perr ? temperature_c(f4::kProduct, *product_scale_) : perr;
    if (!product) return product.error();
    product_c_ = perr.value() != 0 ? std::numeric_limits<double>::quiet_NaN() : product.value();
  }
  return {};  // a read never writes: humidity control is switched off by command() only
}

Result<ChamberState> WatlowF4Chamber::read() {
  auto sc = scale();
  if (!sc) return sc.error();
  const bool full = readback_.due(client_.connects());
  ChamberState s;
  auto err = client_.read(map_.at(f4::kAirError));
  auto air = err ? temperature_c(f4::kAir, sc.value()) : Result<double>(err.error());
  auto sp = air ? temperature_c(f4::kSetpoint, sc.value()) : air;
  Result<void> cmds = sp ? (full ? read_commands() : Result<void>{}) : sp.error();
  readback_.read_done(cmds.ok(), full, client_.connects());
  if (!cmds) return cmds.error();
  s.alarms.sensor_break = err.value() != 0;  // F4P p. 9.6: 0 none, 1..6 an input error
  s.air_c = s.alarms.sensor_break ? std::numeric_limits<double>::quiet_NaN() : air.value();
  s.setpoint_c = sp.value();
  s.product_c = inputs_.product_input == 0 ? std::numeric_limits<double>::quiet_NaN() : product_c_;
  s.mode = mode_;
  s.run_enabled = run_enabled_;
  s.ramp_c_per_min = 0;  // no constant-mode ramp on an F4
  return s;
}

PlausibleRange WatlowF4Chamber::air_range_c() const {
  const TemperatureScale s = scale_.value_or(TemperatureScale{});
  return PlausibleRange{s.c_from_raw(-32767), s.c_from_raw(32767)} & Chamber::air_range_c();
}

double WatlowF4Chamber::setpoint_resolution_c() const {
  const TemperatureScale s = scale_.value_or(TemperatureScale{});
  return s.delta_to_c(std::pow(10.0, -s.decimals));
}

// The setpoint limits: 602/603 where the map serves them, else the configured ones, else none
// (the station's [limits] still bound every setpoint).
Result<std::pair<double, double>> WatlowF4Chamber::setpoint_limits_c(const TemperatureScale& s) {
  if (map_.find(f4::kSetpointLow) == nullptr)
    return std::pair{inputs_.setpoint_low_c.value_or(-std::numeric_limits<double>::infinity()),
                     inputs_.setpoint_high_c.value_or(std::numeric_limits<double>::infinity())};
  auto lo = temperature_c(f4::kSetpointLow, s);
  if (!lo) return lo.error();
  auto hi = temperature_c(f4::kSetpointHigh, s);
  if (!hi) return hi.error();
  return std::pair{lo.value(), hi.value()};
}

// Humidity control off: the humidity event output (TestEquity wiring, f4_map.hpp), if mapped.
Result<void> WatlowF4Chamber::humidity_off() {
  const auto* ev = map_.find(f4::kHumidityEvent);
  if (ev == nullptr) return {};
  auto now = client_.read(*ev);
  if (!now) return now.error();
  if (now.value() == f4::kEventOff) return {};
  return client_.write(*ev, f4::kEventOff);
}

Result<void> WatlowF4Chamber::command(const ChamberCommand& c) {
  readback_.invalidate();
  auto sc = scale();
  if (!sc) return sc.error();
  if (c.setpoint_c) {
    auto limits = setpoint_limits_c(sc.value());
    if (!limits) return limits.error();
    const auto [lo, hi] = limits.value();
    const auto raw = sc.value().raw_from_c(*c.setpoint_c);
    if (!std::isfinite(*c.setpoint_c) || *c.setpoint_c < lo - 1e-9 || *c.setpoint_c > hi + 1e-9 ||
        !raw)
      return make_error(ErrorKind::range,
                        fmt::format("{}: setpoint {} C outside the chamber limits [{}, {}] C",
                                    name_, *c.setpoint_c, lo, hi));
    if (auto ok = client_.write(map_.at(f4::kSetpoint), *raw); !ok) return ok;
  }
  if (c.run) {
    if (*c.run && humidity_chamber_) {
      if (auto off = humidity_off(); !off) return off;
    }
    const int v = *c.run ? f4::kEventOn : f4::kEventOff;
    if (auto ok = client_.write(map_.at(f4::kRunEvent), v); !ok) return ok;
  }
  return {};
}

Result<ChamberIdentity> WatlowF4Chamber::identify() {
  auto sc = scale();
  if (!sc) return sc.error();
  auto limits = setpoint_limits_c(sc.value());
  if (!limits) return limits.error();
  const bool served = map_.find(f4::kSetpointLow) != nullptr;
  ChamberIdentity id;
  id.model = model_;
  id.identity = "Watlow F4 map (no identity register in the sources)";
  id.units = sc.value().fahrenheit ? "F" : "C";
  id.decimals = sc.value().decimals;
  id.setpoint_low_c = limits.value().first;
  id.setpoint_high_c = limits.value().second;
  const auto* hum = map_.find(f4::kHumidityEvent);
  const std::string humidity =
      !humidity_chamber_ ? std::string()
      : hum != nullptr   ? fmt::format(
                               "humidity chamber (input 2 is %RH): humidity control (event "
                                 "output at register {}) switched off when the station "
                                 "starts the chamber; ",
                               hum->address)
                       : std::string(
                             "humidity chamber (input 2 is %RH): no humidity event "
                             "configured, humidity control NOT switched off; ");
  id.notes = fmt::format(
      "{}run = event output at register {}; no constant-mode ramp: the station ramps the "
      "setpoint; product: {}; {}{}",
      sc.value().fahrenheit ? "deg F converted to deg C; " : "", map_.at(f4::kRunEvent).address,
      inputs_.product_input == 0 ? "none configured (product_input = 0)" : "input 2 (104)",
      humidity,
      served ? "setpoint limits read from 602/603"
             : (inputs_.setpoint_low_c || inputs_.setpoint_high_c
                    ? "Data Map 2 serves no setpoint limits: the configured ones apply"
                    : "Data Map 2 serves no setpoint limits (set setpoint_low_c/high_c): the "
                      "station's [limits] apply"));
  return id;
}

}  // namespace station::drivers
