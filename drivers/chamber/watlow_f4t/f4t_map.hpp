// Watlow F4T Modbus "Data Map 1" (dialect "watlow_f4t"). Wire definition shared by
// WatlowF4tChamber and the simulator's F4T face; tests/drivers/test_dialect_conformance.cpp
// checks it against the table transcribed from the sources (docs/DEVICES.md).
//
// Sources: [CCL] ESPEC North America ChamberConnectLibrary (MIT) @1d2deb8,
// chamberconnectlibrary/watlowf4t.py and modbus.py; [TE] TestEquity F4T Controller manual
// (ramp action/scale/rate p. 46 and 52; event 2 is humidity in humidity models p. 51).
// Holding registers, 0-based PDU addresses (CCL modbus.py _make_packet:325-333); analog values are
// IEEE-754 floats with the LOW word first (CDAB; CCL modbus.py read_holding_float:157-173);
// enumerations are single uint16 registers with Watlow's enumeration codes.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers::watlow_f4t {

using modbus::Access;
using modbus::Point;
using modbus::PointType;
using modbus::RegisterMap;

inline constexpr const char* kAir = "loop1_pv";               // 2820, CCL get_loop_pv:243-247
inline constexpr const char* kProduct = "loop2_pv";           // 2980 = 2820 + 160, same
inline constexpr const char* kSetpoint = "loop1_sp";          // 2782, CCL get_loop_sp:234, set:241
inline constexpr const char* kWorkingSetpoint = "loop1_wsp";  // 2810, CCL get_loop_sp:235
inline constexpr const char* kSetpointLow = "loop1_sp_min";   // 2774, CCL get_loop_range:256-259
inline constexpr const char* kSetpointHigh = "loop1_sp_max";  // 2776, same
inline constexpr const char* kLoopMode = "loop1_mode";  // 2814 current mode, CCL get_loop_en:264
inline constexpr const char* kRampAction = "loop1_ramp_action";  // 2794 [TE] p. 46, 52
inline constexpr const char* kRampScale = "loop1_ramp_scale";    // 2796 [TE] p. 46, 52
inline constexpr const char* kRampRate = "loop1_ramp_rate";      // 2798 [TE] p. 46, 52, float
inline constexpr const char* kProfileState = "profile_state";    // 16568, CCL get_status:528-546
inline constexpr const char* kAlarm1 = "alarm1_state";  // 1356, CCL get_alarm_status:552-556
inline constexpr const char* kRunEvent = "event";       // see kEventRegisters
inline constexpr const char* kUnits =
    "units";  // 6730 TCP / 14080 RTU, CCL __profile_units:990-1007
/// What the air / product loop's process value is: 16536 + 2 (n - 1), CCL __profile_units:997;
/// served with the profile option only (part number character 7 'D'..'F').
inline constexpr const char* kAirKind = "loop1_pv_kind";
inline constexpr const char* kProductKind = "loop2_pv_kind";
/// The event output wired to humidity on a humidity chamber ([TE] TestEquity F4T manual p. 51:
/// "Event 2 is Humidity in Humidity models"), switched off when the station starts the chamber.
inline constexpr const char* kHumidityEvent = "humidity_event";
inline constexpr int kDefaultHumidityEvent = 2;

/// Loop stride: loop n's registers are loop 1's + 160 (n - 1) (CCL get_loop_pv:243-247).
inline constexpr int kLoopStride = 160;
/// Event outputs 1..8 (CCL get_event:499-506).
inline constexpr std::array<std::uint16_t, 8> kEventRegisters{16594, 16596, 16598, 16600,
                                                              16822, 16824, 16826, 16828};
/// Part number: 15 registers from 16, one character each (CCL process_controller:861-921).
inline constexpr std::uint16_t kPartNumberAddress = 16;
inline constexpr int kPartNumberRegisters = 15;
/// Units register: 6730 over TCP, 14080 over RTU (CCL __profile_units:1003-1006).
inline constexpr std::uint16_t kUnitsTcp = 6730, kUnitsRtu = 14080;

/// Watlow enumeration codes (CCL watlowf4t.py __init__:78-121 dictionary and the functions named).
enum Enum : int {
  kAuto = 10,             // loop mode, CCL set_loop_mode:294-309
  kManual = 54,           //
  kOff = 62,              // loop mode off; event off (CCL set_event:508-520); ramp action off
  kOn = 63,               // event on
  kCelsius = 15,          // units (CCL __profile_units)
  kFahrenheit = 30,       //
  kHours = 39,            // ramp scale (dictionary; [TE] names the register)
  kMinutes = 57,          //
  kRampSetpoint = 85,     // ramp action "setpoint" (dictionary)
  kProfilePaused = 146,   // profile state (CCL get_status:528-546)
  kProfileRunning = 149,  //
  kProfileTimedStart = 1783,
};
/// Process value kinds (CCL __profile_units:1000 and the __init__ dictionary:103-112).
enum PvKind : int {
  kAbsoluteTemperature = 1540,
  kRelativeTemperature = 1541,
  kNotSourced = 246,
  kHumidity = 1538
};
/// Part number characters (CCL process_controller:861-921): index 6 'D', 'E', 'F' = profiles;
/// index 11 the control loops: '1'..'4' that many loops, '5' none, '6'..'C' with cascade loops.
inline constexpr int kPartProfilesChar = 6, kPartLoopsChar = 11;
/// Alarm state codes that mean "not active" (CCL get_alarm_status:552-556: startup, none, 12).
inline constexpr std::array<int, 3> kAlarmInactive{88, 61, 12};
/// Alarm state "error" (CCL dictionary:81, 28 'error'; get_alarm_status:558 reads a limit in
/// state 'error' as active): alarm 1's source, the air loop, has an input error -> sensor break
/// (Watlow F4T Install & Troubleshooting p. 34 "Error Input"; the code on alarm 1: A).
inline constexpr int kAlarmError = 28;

/// Name of the i-th part-number register (0..14).
inline std::string part_number_point(int i) {
  return "part_number_" + std::to_string(i);
}

/// The map for air loop `loop` (1..4), chamber-run event output `run_event` (1..8), the units
/// register of the transport (`rtu` true: 14080), the humidity event output `humidity_event` (0:
/// none; not mapped when it is the run event) and the product loop `product_loop` (0: the loop
/// after the air loop).
inline RegisterMap map(int unit_id = 1, int run_event = 1, bool rtu = false, int loop = 1,
                       int humidity_event = kDefaultHumidityEvent, int product_loop = 0) {
  if (product_loop == 0) product_loop = loop + 1;
  const auto off = static_cast<std::uint16_t>(kLoopStride * (loop - 1));
  const auto poff = static_cast<std::uint16_t>(kLoopStride * (product_loop - 1));
  auto p = [unit_id](const char* n, std::uint16_t a, PointType t, Access acc) {
    return Point{n,       a,     t,  1.0, modbus::WordOrder::cdab, modbus::FunctionCode::holding,
                 unit_id, false, acc};
  };
  constexpr auto F = PointType::float32;
  constexpr auto U = PointType::uint16;
  RegisterMap m(
      "watlow_f4t",
      {p(kAir, static_cast<std::uint16_t>(2820 + off), F, Access::ro),
       p(kProduct, static_cast<std::uint16_t>(2820 + poff), F, Access::ro),
       p(kSetpoint, static_cast<std::uint16_t>(2782 + off), F, Access::rw),
       p(kWorkingSetpoint, static_cast<std::uint16_t>(2810 + off), F, Access::ro),
       p(kSetpointLow, static_cast<std::uint16_t>(2774 + off), F, Access::ro),
       p(kSetpointHigh, static_cast<std::uint16_t>(2776 + off), F, Access::ro),
       p(kLoopMode, static_cast<std::uint16_t>(2814 + off), U, Access::ro),
       p(kRampAction, static_cast<std::uint16_t>(2794 + off), U, Access::rw),
       p(kRampScale, static_cast<std::uint16_t>(2796 + off), U, Access::rw),
       p(kRampRate, static_cast<std::uint16_t>(2798 + off), F, Access::rw),
       p(kProfileState, 16568, U, Access::ro), p(kAlarm1, 1356, U, Access::ro),
       p(kRunEvent, kEventRegisters.at(static_cast<std::size_t>(run_event - 1)), U, Access::rw),
       p(kUnits, rtu ? kUnitsRtu : kUnitsTcp, U, Access::ro),
       p(kAirKind, static_cast<std::uint16_t>(16536 + 2 * (loop - 1)), U, Access::ro),
       p(kProductKind, static_cast<std::uint16_t>(16536 + 2 * (product_loop - 1)), U,
         Access::ro)});
  if (humidity_event >= 1 && humidity_event != run_event)
    m.set(p(kHumidityEvent, kEventRegisters.at(static_cast<std::size_t>(humidity_event - 1)), U,
            Access::rw));
  for (int i = 0; i < kPartNumberRegisters; ++i)
    m.set(p(part_number_point(i).c_str(), static_cast<std::uint16_t>(kPartNumberAddress + i), U,
            Access::ro));
  // A loop's process value on an input error (open sensor) is NaN (docs/DEVICES.md: A): a
  // reading the driver judges, not a protocol error.
  for (const char* pv : {kAir, kProduct}) {
    Point pt = m.at(pv);
    pt.nan_on_input_error = true;
    m.set(pt);
  }
  return m;
}

}  // namespace station::drivers::watlow_f4t
