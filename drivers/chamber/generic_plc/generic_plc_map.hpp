// The station's own chamber map, "generic_plc" (wire definition shared by ModbusChamber and the
// generic_plc face of the chamber simulator). NOT a vendor's map: it is what a chamber whose
// controller is a PLC programmed for the station (or a gateway in front of any controller) serves,
// documented in docs/DEVICES.md as the station's definition. Every point can be moved with a
// [[chamber.point]] override. (Before issue 20 this map was mislabelled "watlow_f4"; the Watlow
// dialects now live in drivers/chamber/watlow_f4*/ and follow the maker's documents.)
// Holding registers, 0-based, unit 1, int16 tenths of a degree:
//   100 air   104 product   110 alarm bits (bit0 deviation, bit1 sensor break, bit2 door open,
//   bit3 high-limit trip)   200 status: 0 off, 1 constant, 2 ramping, 3 hold   300 setpoint (rw)
//   310 setpoint ramp, tenths of C/min, 0 = step (rw)   602/603 setpoint low/high limit
//   2000 run enable 0/1 (rw)
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

/// The generic PLC chamber map (see file comment).
inline RegisterMap generic_plc(int unit_id = 1) {
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
  return RegisterMap("generic_plc", {t(kAir, 100, Access::ro), t(kProduct, 104, Access::ro),
                                     u(kAlarms, 110, Access::ro), u(kStatus, 200, Access::ro),
                                     t(kSetpoint, 300, Access::rw), t(kRamp, 310, Access::rw),
                                     t(kSetpointLow, 602, Access::ro),
                                     t(kSetpointHigh, 603, Access::ro), u(kRun, 2000, Access::rw)});
}

/// The same points as 32-bit floats, low word first (CDAB), for a PLC that serves floats
/// (driver tests and fuzzers exercise the float codec through it): 2800 air, 2880 product,
/// 2920 status, 1500 alarm bits, 2160 setpoint, 2168 ramp, 2172/2174 limits, 2040 run.
inline RegisterMap generic_plc_float(int unit_id = 1) {
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
  return RegisterMap(
      "generic_plc_float",
      {f(kAir, 2800, Access::ro), f(kProduct, 2880, Access::ro), u(kStatus, 2920, Access::ro),
       u(kAlarms, 1500, Access::ro), f(kSetpoint, 2160, Access::rw), f(kRamp, 2168, Access::rw),
       f(kSetpointLow, 2172, Access::ro), f(kSetpointHigh, 2174, Access::ro),
       u(kRun, 2040, Access::rw)});
}

}  // namespace station::drivers::chamber_map
