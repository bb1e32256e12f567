// ModbusTurntable: decodes table state and range-checks demands.
#include "drivers/turntable/generic_plc/modbus_turntable.hpp"

#include <fmt/format.h>

#include <cmath>

#include "drivers/turntable/generic_plc/generic_plc_map.hpp"

namespace station::drivers {
namespace tm = turntable_map;

ModbusTurntable::ModbusTurntable(std::string name, modbus::Endpoint endpoint,
                                 modbus::RegisterMap map, TurntableLimits limits,
                                 double response_timeout_s,
                                 std::unique_ptr<modbus::ModbusWire> wire)
    : name_(std::move(name)),
      map_(std::move(map)),
      limits_(limits),
      client_(name_, endpoint,
              wire ? std::move(wire) : std::make_unique<modbus::LibmodbusWire>(endpoint),
              response_timeout_s) {
  for (const char* p : {tm::kModeDemand, tm::kPositionDemand, tm::kRateDemand, tm::kLock, tm::kStop,
                        tm::kAngle, tm::kRate, tm::kStatus, tm::kModeActual})
    (void)map_.at(p);
  for (const char* p : {tm::kModeActual, tm::kAngle, tm::kRate, tm::kStatus}) {
    read_points_.push_back(map_.at(p));
  }
  // Same coalescing rule as the chamber (gap <= 16 registers, one unit and function code).
  read_plan_ = modbus::plan_reads(read_points_, 16);
}

Result<void> ModbusTurntable::connect() {
  return client_.connect();
}

Result<TurntableState> ModbusTurntable::read() {
  // One block read of the input registers 100..105 (see turntable_map.hpp) instead of four.
  auto values = client_.read_points(read_points_, read_plan_);
  if (!values) {
    readback_.invalidate();
    return values.error();
  }
  const auto& v = values.value();  // mode, angle, rate, status: the order of kReadPoints
  const int m = static_cast<int>(v[0]);
  if (m < 0 || m > 2)
    return make_error(ErrorKind::protocol, fmt::format("{}: mode register {} not 0..2", name_, m));
  TurntableState s;
  s.mode = static_cast<TurntableMode>(m);
  s.angle_deg = v[1];
  s.rate_dps = v[2];
  const auto bits = static_cast<unsigned>(v[3]);
  s.in_position = (bits & tm::kInPosition) != 0;
  s.at_rate = (bits & tm::kAtRate) != 0;
  s.fault = (bits & tm::kFault) != 0;
  s.interlock_open = (bits & tm::kInterlockOpen) != 0;
  if (readback_.due(client_.connects())) {
    auto lock = client_.read(map_.at(tm::kLock));
    readback_.read_done(lock.ok(), true, client_.connects());
    if (!lock) return lock.error();
    locked_ = lock.value() != 0;
  } else {
    readback_.read_done(true, false, client_.connects());
  }
  s.locked = locked_;
  return s;
}

Result<void> ModbusTurntable::check(const TurntableCommand& c) const {
  if (c.position_deg && !std::isfinite(*c.position_deg))
    return make_error(ErrorKind::range, name_ + ": position demand is not finite");
  if (c.rate_dps && !(std::fabs(*c.rate_dps) <= limits_.max_rate_dps))
    return make_error(ErrorKind::range, fmt::format("{}: rate {} deg/s beyond +-{} deg/s", name_,
                                                    *c.rate_dps, limits_.max_rate_dps));
  return {};
}

Result<void> ModbusTurntable::command(const TurntableCommand& c) {
  if (auto ok = check(c); !ok) return ok;
  readback_.invalidate();  // the next read confirms what the drive took
  // A release goes out before the demands; an engage after them (a locked axis does not move, and
  // the drive engages the lock only at rest: the caller waits for in-position before locking).
  if (c.lock && !*c.lock) {
    if (auto ok = client_.write(map_.at(tm::kLock), 0); !ok) return ok;
  }
  if (c.position_deg) {
    double wrapped = std::fmod(std::fmod(*c.position_deg, 360.0) + 360.0, 360.0);
    if (auto ok = client_.write(map_.at(tm::kPositionDemand), wrapped); !ok) return ok;
  }
  if (c.rate_dps) {
    if (auto ok = client_.write(map_.at(tm::kRateDemand), *c.rate_dps); !ok) return ok;
  }
  if (auto ok = client_.write(map_.at(tm::kModeDemand), static_cast<double>(c.mode)); !ok)
    return ok;
  if (c.lock && *c.lock) return client_.write(map_.at(tm::kLock), 1);
  return {};
}

Result<void> ModbusTurntable::stop() {
  return client_.write(map_.at(tm::kStop), 1);
}

}  // namespace station::drivers
