// ModbusChamber: decodes chamber state from the register map and range-checks commands.
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"

namespace station::drivers {
namespace cm = chamber_map;

namespace {

// The points read() fetches; values come back in this order.
// Live points first, read on every read: what the safety layer judges every tick — alarms (door,
// high-limit trip, sensor break), air, and the setpoint (one written at the panel out of limits
// must be caught before the station's next write would hide it). Then the points read with the
// command registers (modbus/readback.hpp): ramp and run, and two informational ones no record or
// safety rule uses (probe shows them): the controller's status and the product temperature.
constexpr std::array kReadPoints{cm::kAlarms,  cm::kAir,  cm::kSetpoint, cm::kStatus,
                                 cm::kProduct, cm::kRamp, cm::kRun};
constexpr std::size_t kLivePoints = 3;
enum ReadField : std::size_t { kAlarmsF, kAirF, kSetpointF, kStatusF, kProductF, kRampF, kRunF };

AlarmBits decode_alarms(unsigned bits) {
  return AlarmBits{(bits & cm::kDeviation) != 0, (bits & cm::kSensorBreak) != 0,
                   (bits & cm::kDoorOpen) != 0, (bits & cm::kHighLimitTrip) != 0};
}

}  // namespace

ModbusChamber::ModbusChamber(std::string name, modbus::Endpoint endpoint, modbus::RegisterMap map,
                             double response_timeout_s, std::unique_ptr<modbus::ModbusWire> wire)
    : name_(std::move(name)),
      map_(std::move(map)),
      client_(name_, endpoint,
              wire ? std::move(wire) : std::make_unique<modbus::LibmodbusWire>(endpoint),
              response_timeout_s) {
  for (const char* p : {cm::kAir, cm::kProduct, cm::kStatus, cm::kAlarms, cm::kSetpoint, cm::kRamp,
                        cm::kSetpointLow, cm::kSetpointHigh, cm::kRun})
    (void)map_.at(p);  // throws naming the missing point
  for (const char* p : kReadPoints) read_points_.push_back(map_.at(p));
  limit_points_ = {map_.at(cm::kSetpointLow), map_.at(cm::kSetpointHigh)};
  limit_plan_ = modbus::plan_each(limit_points_);
  set_max_read_gap(kDefaultMaxReadGap);
}

void ModbusChamber::set_max_read_gap(int registers) {
  read_plan_ = modbus::plan_reads(read_points_, registers);
  live_plan_ = modbus::plan_reads(std::span(read_points_).first(kLivePoints), registers);
}

Result<void> ModbusChamber::connect() {
  return client_.connect();
}

Result<std::vector<double>> ModbusChamber::read_values() {
  const bool full = readback_.due(client_.connects());
  auto values = full ? client_.read_points(read_points_, read_plan_)
                     : client_.read_points(std::span(read_points_).first(kLivePoints), live_plan_);
  if (values && full) {
    const auto& v = values.value();
    const int st = static_cast<int>(v[kStatusF]);
    if (st < 0 || st > 3) {
      readback_.read_done(false, full, client_.connects());
      return make_error(ErrorKind::protocol,
                        fmt::format("{}: status register {} not 0..3", name_, st));
    }
    mode_ = static_cast<ChamberMode>(st);
    product_c_ = v[kProductF];
    ramp_c_per_min_ = v[kRampF];
    run_enabled_ = v[kRunF] != 0;
  }
  readback_.read_done(values.ok(), full, client_.connects());
  return values;
}

Result<ChamberState> ModbusChamber::read() {
  auto values = read_values();
  if (!values) return values.error();
  const auto& v = values.value();
  ChamberState s;
  s.alarms = decode_alarms(static_cast<unsigned>(v[kAlarmsF]));
  s.mode = mode_;
  s.air_c = v[kAirF];
  s.product_c = product_c_;
  s.setpoint_c = v[kSetpointF];
  s.ramp_c_per_min = ramp_c_per_min_;
  s.run_enabled = run_enabled_;
  // On sensor break the controller's air value is meaningless; never let it reach a record.
  if (s.alarms.sensor_break) s.air_c = std::numeric_limits<double>::quiet_NaN();
  return s;
}

Result<std::vector<double>> ModbusChamber::limits() {
  return client_.read_points(limit_points_, limit_plan_);
}

Result<void> ModbusChamber::check_setpoint(double setpoint_c) {
  const auto lim = limits();
  if (!lim) return lim.error();
  const double lo = lim.value()[0], hi = lim.value()[1];
  if (!std::isfinite(setpoint_c) || setpoint_c < lo || setpoint_c > hi)
    return make_error(ErrorKind::range,
                      fmt::format("{}: setpoint {} C outside the chamber limits [{}, {}] C", name_,
                                  setpoint_c, lo, hi));
  return {};
}

Result<ChamberIdentity> ModbusChamber::identify() {
  const auto lim = limits();
  if (!lim) return lim.error();
  ChamberIdentity id;
  id.model = "generic_plc";
  id.identity = "station map '" + map_.device() + "' (no identity register)";
  id.units = "C";
  id.setpoint_low_c = lim.value()[0];
  id.setpoint_high_c = lim.value()[1];
  id.notes = "scaling from the map";
  return id;
}

Result<void> ModbusChamber::command(const ChamberCommand& c) {
  readback_.invalidate();  // the next read confirms what the controller took
  if (c.ramp_c_per_min && !(*c.ramp_c_per_min >= 0 && std::isfinite(*c.ramp_c_per_min)))
    return make_error(ErrorKind::range,
                      fmt::format("{}: ramp {} C/min must be >= 0", name_, *c.ramp_c_per_min));
  if (c.setpoint_c) {
    if (auto ok = check_setpoint(*c.setpoint_c); !ok) return ok;
  }
  if (c.ramp_c_per_min) {
    if (auto ok = client_.write(map_.at(cm::kRamp), *c.ramp_c_per_min); !ok) return ok;
  }
  if (c.setpoint_c) {
    if (auto ok = client_.write(map_.at(cm::kSetpoint), *c.setpoint_c); !ok) return ok;
  }
  if (c.run) {
    if (auto ok = client_.write(map_.at(cm::kRun), *c.run ? 1.0 : 0.0); !ok) return ok;
  }
  return {};
}

}  // namespace station::drivers
