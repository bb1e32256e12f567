// Watlow Series F4P Modbus map (dialect "watlow_f4p"): a single-loop process/temperature
// controller used on small chambers. Wire definition shared by WatlowF4pChamber and the
// simulator's F4P face; tests/drivers/test_dialect_conformance.cpp checks it against the table
// transcribed from the source (docs/DEVICES.md).
//
// Source: [F4P] Watlow Series F4P User's Manual, 0600-0032-0013 Rev E, August 2011 (public copy in
// github.com/IEAv-EFO/acutrol3000, doc/), Chapter 9 "Communications" and the parameter tables of
// Chapter 6; pages as printed. Registers are "relative" = 0-based PDU addresses (p. 9.2). Values
// are signed 16-bit integers with the implied decimals of register 606 (p. 6.13) in the unit of
// register 901 (0 deg F, 1 deg C; p. 6.11).
#pragma once

#include <cstdint>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers::watlow_f4p {

using modbus::Access;
using modbus::Point;
using modbus::PointType;
using modbus::RegisterMap;

inline constexpr const char* kModel = "model";                 // 0, p. 6.27, 9.7: 5280 on an F4P
inline constexpr const char* kAir = "input1_pv";               // 100, p. 9.6, 9.11
inline constexpr const char* kAirError = "input1_err";         // 101, p. 9.6: 0 none, 1..6 error
inline constexpr const char* kAlarm1 = "alarm1_status";        // 102, p. 9.2: 0 off, 1 high, 2 low
inline constexpr const char* kOperation = "auto_manual";       // 200, p. 9.2, 9.7: 1 auto, 2 manual
inline constexpr const char* kControlSetpoint = "control_sp";  // 298, p. 9.4 (in use, ramping)
inline constexpr const char* kSetpoint = "setpoint1";          // 300, p. 9.9
inline constexpr const char* kSetpointLow = "sp_low1";         // 602, p. 6.13, 9.9
inline constexpr const char* kSetpointHigh = "sp_high1";       // 603, p. 6.13, 9.9
inline constexpr const char* kDecimals = "decimals1";          // 606, p. 6.13, 9.4
inline constexpr const char* kUnits = "units";                 // 901, p. 6.11, 9.2
inline constexpr const char* kRampMode = "ramp_mode";          // 1100, p. 6.7, 9.8
inline constexpr const char* kRampRate = "ramp_rate";    // 1101, p. 6.8, 9.8 (implied decimals)
inline constexpr const char* kRampScale = "ramp_scale";  // 1102, p. 6.8, 9.8

/// Register 0 on an F4P: "P4 (4P) ASCII 5280 Dec" (p. 6.27).
inline constexpr int kModelF4p = 5280;
enum Operation : int { kAuto = 1, kManual = 2 };                                   // 200 (p. 9.2)
enum RampMode : int { kRampOff = 0, kRampStartup = 1, kRampStartupOrChange = 2 };  // 1100
enum RampScale : int { kPerMinute = 0, kPerHour = 1 };                             // 1102 (p. 6.8)
inline constexpr int kUnitsFahrenheit = 0, kUnitsCelsius = 1;                      // 901 (p. 6.11)

inline RegisterMap map(int unit_id = 1) {
  auto p = [unit_id](const char* n, std::uint16_t a, PointType t, Access acc) {
    return Point{n,       a,     t,  1.0, modbus::WordOrder::abcd, modbus::FunctionCode::holding,
                 unit_id, false, acc};
  };
  constexpr auto I = PointType::int16;
  constexpr auto U = PointType::uint16;
  return RegisterMap("watlow_f4p",
                     {p(kModel, 0, U, Access::ro), p(kAir, 100, I, Access::ro),
                      p(kAirError, 101, U, Access::ro), p(kAlarm1, 102, U, Access::ro),
                      p(kOperation, 200, U, Access::rw), p(kControlSetpoint, 298, I, Access::ro),
                      p(kSetpoint, 300, I, Access::rw), p(kSetpointLow, 602, I, Access::ro),
                      p(kSetpointHigh, 603, I, Access::ro), p(kDecimals, 606, U, Access::ro),
                      p(kUnits, 901, U, Access::ro), p(kRampMode, 1100, U, Access::rw),
                      p(kRampRate, 1101, I, Access::rw), p(kRampScale, 1102, U, Access::rw)});
}

}  // namespace station::drivers::watlow_f4p
