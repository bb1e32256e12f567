// Chamber register-map presets (wire definitions shared by ModbusChamber and ChamberSim).
//
// "watlow_f4" follows the Watlow Series F4 Modbus map (F4 user's manual, Modbus register list):
//   100 input 1 (air) process value, int16 x0.1 °C     104 input 2 (product) value, int16 x0.1 °C
//   110 alarm bits (bit0 deviation, bit1 sensor break, bit2 door open, bit3 high-limit trip)
//   200 status: 0 off, 1 constant, 2 ramping, 3 hold   300 setpoint, rw int16 x0.1 °C
//   310 setpoint ramp rate, rw int16 x0.1 °C/min, 0 = step
//   602/603 setpoint low/high limit, int16 x0.1 °C      2000 run enable, rw 0/1
// "f4t" is F4T-style: 32-bit floats, CDAB word order (low word first), holding registers,
// 0-based. These addresses are plausible placeholders modelled on the F4T's float layout, NOT
// copied from a Watlow data sheet: override them point by point from the unit's own map.
//   2800 air °C   2880 product °C   2920 status (uint16)   1500 alarm bits (uint16)
//   2160 setpoint °C (rw)   2168 ramp °C/min (rw)   2172 setpoint low limit   2174 high limit
//   2040 run enable (uint16, rw)
#pragma once

#include <stdexcept>
#include <string>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers::chamber_map {

using modbus::Access;
using modbus::Point;
using modbus::PointType;
using modbus::RegisterMap;
using modbus::WordOrder;

/// Point names every chamber map defines.
inline constexpr const char* kAir = "air_c";
inline constexpr const char* kProduct = "product_c";
inline constexpr const char* kStatus = "status";
inline constexpr const char* kAlarms = "alarms";
inline constexpr const char* kSetpoint = "setpoint_c";
inline constexpr const char* kRamp = "ramp_c_per_min";
inline constexpr const char* kSetpointLow = "setpoint_low_c";
inline constexpr const char* kSetpointHigh = "setpoint_high_c";
inline constexpr const char* kRun = "run";

/// Alarm-register bit positions.
enum AlarmBit : unsigned {
  kDeviation = 1u << 0,
  kSensorBreak = 1u << 1,
  kDoorOpen = 1u << 2,
  kHighLimitTrip = 1u << 3
};

/// Watlow F4 map: int16 tenths of a degree, holding registers, unit 1.
inline RegisterMap watlow_f4(int unit_id = 1) {
  auto t = [unit_id](const char* n, std::uint16_t a, Access acc) {
    return Point{
        n,     a,  PointType::int16, 0.1, WordOrder::abcd, modbus::FunctionCode::holding, unit_id,
        false, acc};
  };
  auto u = [unit_id](const char* n, std::uint16_t a, Access acc) {
    return Point{
        n,     a,  PointType::uint16, 1.0, WordOrder::abcd, modbus::FunctionCode::holding, unit_id,
        false, acc};
  };
  return RegisterMap("watlow_f4", {t(kAir, 100, Access::ro), t(kProduct, 104, Access::ro),
                                   u(kAlarms, 110, Access::ro), u(kStatus, 200, Access::ro),
                                   t(kSetpoint, 300, Access::rw), t(kRamp, 310, Access::rw),
                                   t(kSetpointLow, 602, Access::ro),
                                   t(kSetpointHigh, 603, Access::ro), u(kRun, 2000, Access::rw)});
}

/// F4T-style map: float32 CDAB °C, holding registers, unit 1 (addresses: see file comment).
inline RegisterMap f4t(int unit_id = 1) {
  auto f = [unit_id](const char* n, std::uint16_t a, Access acc) {
    return Point{
        n,     a,  PointType::float32, 1.0, WordOrder::cdab, modbus::FunctionCode::holding, unit_id,
        false, acc};
  };
  auto u = [unit_id](const char* n, std::uint16_t a, Access acc) {
    return Point{
        n,     a,  PointType::uint16, 1.0, WordOrder::abcd, modbus::FunctionCode::holding, unit_id,
        false, acc};
  };
  return RegisterMap("f4t", {f(kAir, 2800, Access::ro), f(kProduct, 2880, Access::ro),
                             u(kStatus, 2920, Access::ro), u(kAlarms, 1500, Access::ro),
                             f(kSetpoint, 2160, Access::rw), f(kRamp, 2168, Access::rw),
                             f(kSetpointLow, 2172, Access::ro), f(kSetpointHigh, 2174, Access::ro),
                             u(kRun, 2040, Access::rw)});
}

/// Preset by name ("watlow_f4", "f4t"); throws std::invalid_argument naming the bad name.
inline RegisterMap preset(const std::string& name, int unit_id = 1) {
  if (name == "watlow_f4") return watlow_f4(unit_id);
  if (name == "f4t") return f4t(unit_id);
  throw std::invalid_argument("unknown chamber register-map preset '" + name +
                              "' (expected watlow_f4 or f4t)");
}

}  // namespace station::drivers::chamber_map
