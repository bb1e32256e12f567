// Watlow Series F4 (F4S/F4D) Modbus map, and the same map served by an F4T in its
// F4-compatibility mode (dialect "watlow_f4t_map2"). Wire definition shared by WatlowF4Chamber
// and the simulator's F4 face; tests/drivers/test_dialect_conformance.cpp checks it against the
// table transcribed from the sources below (docs/DEVICES.md).
//
// Sources: [CCL] ESPEC North America ChamberConnectLibrary (MIT) @1d2deb8,
// chamberconnectlibrary/watlowf4.py; [F4P] Watlow Series F4P User's Manual 0600-0032-0013 Rev E
// (same register family, pages as printed), used where CCL is silent; for Data Map 2 [TE]
// TestEquity F4T Controller manual p. 47 and [TE101H] TestEquity 101H manual p. 61.
// Registers are 0-based PDU addresses (CCL modbus.py _make_packet; F4P p. 9.2 "add 40001").
// Values are signed 16-bit integers with the input's implied decimal places (606) in the unit
// chosen by 901 (CCL watlowf4.py get_loop_pv/__get_scalar/get_loop_units; F4P p. 6.13, 9.4).
#pragma once

#include <cstdint>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers::watlow_f4 {

using modbus::Access;
using modbus::Point;
using modbus::PointType;
using modbus::RegisterMap;

/// Point names (raw register values; scaling is the driver's, from kDecimals and kUnits).
inline constexpr const char* kAir = "input1_pv";        // 100, CCL get_loop_pv:349-352
inline constexpr const char* kAirError = "input1_err";  // 101, F4P p. 9.6 (0 none, 1..6 error)
inline constexpr const char* kProduct = "input2_pv";    // 104, CCL get_loop_pv:349-352 (loop 2)
inline constexpr const char* kProductError =
    "input2_err";                                 // 105, F4 map (assumption, F4P p. 9.6 pattern)
inline constexpr const char* kStatus = "status";  // 200, CCL get_status:545-554
inline constexpr const char* kSetpoint = "setpoint1";   // 300, CCL get_loop_sp:329, set_loop_sp:342
inline constexpr const char* kSetpointLow = "sp_low1";  // 602, CCL get_loop_range:354-360
inline constexpr const char* kSetpointHigh = "sp_high1";  // 603, CCL get_loop_range:354-360
inline constexpr const char* kDecimals = "decimals1";  // 606, CCL __get_scalar:100-115; F4P p. 6.13
inline constexpr const char* kDecimals2 = "decimals2";  // 616, CCL __get_scalar:100-115
inline constexpr const char* kUnits = "units";          // 901, CCL get_loop_units:396; F4P p. 6.11
inline constexpr const char* kRunEvent = "event";       // 2000 + 10(n-1), CCL get_event:533-543
inline constexpr const char* kInput1Units = "input1_units";  // 608, CCL get_loop_units:392-397
inline constexpr const char* kInput2Units = "input2_units";  // 618, same
/// The event output wired to humidity on a humidity chamber ([TE] p. 51: "Event 2 is Humidity
/// in Humidity models"), switched off when the station starts the chamber.
inline constexpr const char* kHumidityEvent = "humidity_event";
inline constexpr int kDefaultHumidityEvent = 2;

/// Status register 200 values (CCL get_status:545-554): 0 and 1 constant, 2 profile running,
/// 3 profile paused. No "off", no "ramping": an F4 ramps only inside a profile.
enum Status : int { kConstant0 = 0, kConstant1 = 1, kProfileRunning = 2, kProfilePaused = 3 };
/// Register 901 (CCL get_loop_units:396: non-zero is deg C; F4P p. 6.11: 0 deg F, 1 deg C).
inline constexpr int kUnitsFahrenheit = 0;
/// What an input measures, 608/618 (CCL get_loop_units:394: 0 temperature, 1 %RH, 2 PSI, 3 none).
enum InputKind : int { kTemperature = 0, kHumidity = 1, kPressure = 2, kNoInput = 3 };
/// Event output values (CCL get_event/set_event:533-543).
inline constexpr int kEventOff = 0, kEventOn = 1;

/// Register of event output n (1..8): 2000 + 10 (n - 1) (CCL get_event:533-537).
constexpr std::uint16_t event_register(int n) {
  return static_cast<std::uint16_t>(2000 + 10 * (n - 1));
}

namespace detail {
inline Point point(int unit_id, const char* n, std::uint16_t a, PointType t, Access acc) {
  return Point{n,       a,     t,  1.0, modbus::WordOrder::abcd, modbus::FunctionCode::holding,
               unit_id, false, acc};
}
inline void add_humidity_event(RegisterMap& m, int unit_id, int run_event, int humidity_event) {
  if (humidity_event >= 1 && humidity_event != run_event)
    m.set(point(unit_id, kHumidityEvent, event_register(humidity_event), PointType::uint16,
                Access::rw));
}
}  // namespace detail

/// The map for unit `unit_id` with the chamber-run event output `run_event` (1..8; which event
/// runs the chamber is the chamber builder's wiring, so it is configuration) and the humidity
/// event output `humidity_event` (0: none; not served when it is the run event).
inline RegisterMap map(int unit_id = 1, int run_event = 1, const char* name = "watlow_f4",
                       int humidity_event = kDefaultHumidityEvent) {
  auto p = [unit_id](const char* n, std::uint16_t a, PointType t, Access acc) {
    return detail::point(unit_id, n, a, t, acc);
  };
  constexpr auto I = PointType::int16;
  constexpr auto U = PointType::uint16;
  RegisterMap m(name, {p(kAir, 100, I, Access::ro), p(kAirError, 101, U, Access::ro),
                       p(kProduct, 104, I, Access::ro), p(kProductError, 105, U, Access::ro),
                       p(kStatus, 200, U, Access::ro), p(kSetpoint, 300, I, Access::rw),
                       p(kSetpointLow, 602, I, Access::ro), p(kSetpointHigh, 603, I, Access::ro),
                       p(kDecimals, 606, U, Access::ro), p(kDecimals2, 616, U, Access::ro),
                       p(kInput1Units, 608, U, Access::ro), p(kInput2Units, 618, U, Access::ro),
                       p(kUnits, 901, U, Access::ro),
                       p(kRunEvent, event_register(run_event), U, Access::rw)});
  detail::add_humidity_event(m, unit_id, run_event, humidity_event);
  return m;
}

/// An F4T in Data Map 2 (dialect "watlow_f4t_map2"): only the registers [TE] p. 47 and [TE101H]
/// p. 61 list — 100/101 air and its error, 104/105 the chamber HUMIDITY and its error, 300, 606,
/// 616, 901, events 2000 + 10 (n - 1). No status (200), no setpoint limits (602/603), no input
/// units (608/618). Not served by F4Ts with cascade control ([TE] p. 47, 52).
inline RegisterMap map2(int unit_id = 1, int run_event = 1,
                        int humidity_event = kDefaultHumidityEvent) {
  auto p = [unit_id](const char* n, std::uint16_t a, PointType t, Access acc) {
    return detail::point(unit_id, n, a, t, acc);
  };
  constexpr auto I = PointType::int16;
  constexpr auto U = PointType::uint16;
  RegisterMap m("watlow_f4t_map2",
                {p(kAir, 100, I, Access::ro), p(kAirError, 101, U, Access::ro),
                 p(kProduct, 104, I, Access::ro), p(kProductError, 105, U, Access::ro),
                 p(kSetpoint, 300, I, Access::rw), p(kDecimals, 606, U, Access::ro),
                 p(kDecimals2, 616, U, Access::ro), p(kUnits, 901, U, Access::ro),
                 p(kRunEvent, event_register(run_event), U, Access::rw)});
  detail::add_humidity_event(m, unit_id, run_event, humidity_event);
  return m;
}

}  // namespace station::drivers::watlow_f4
