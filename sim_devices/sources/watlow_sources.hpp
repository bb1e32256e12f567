// The Watlow controllers' registers and codes as their makers' documents give them, transcribed
// by hand: the simulated F4, F4T and F4P speak from these tables, and the conformance test
// (tests/drivers/test_dialect_conformance.cpp) holds each driver's own map against them, so the
// driver's map and the simulator's are two readings of one document and a driver-simulator run
// is a conformance check. Nothing here comes from drivers/chamber/ (docs/DEVICES.md).
//
// [CCL] ESPEC North America ChamberConnectLibrary (MIT) @1d2deb8, chamberconnectlibrary/
// watlowf4.py, watlowf4t.py, modbus.py. [F4P] Watlow Series F4P User's Manual 0600-0032-0013
// Rev E, pages as printed. [TE] TestEquity F4T Controller manual (easymanua.ls/testequity/f4t,
// pages as printed: p. 46 Data Map 1, p. 47 Data Map 2, p. 51-52 programming syntax). [TE101H]
// TestEquity 101H Temperature/Humidity Chamber manual, chapter 6 (manualshive.com, p. 60-61).
// Addresses are 0-based PDU addresses (CCL modbus.py _make_packet:325-333; F4P p. 9.2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/modbus/register_map.hpp"

namespace station::sim::sources {

/// One holding register (or float pair) as a document gives it.
struct SourcePoint {
  std::string name;  ///< the station's name for it (the drivers' maps use the same names)
  std::uint16_t address = 0;
  drivers::modbus::PointType type = drivers::modbus::PointType::uint16;
  drivers::modbus::WordOrder order = drivers::modbus::WordOrder::abcd;
  bool writable = false;
  std::string source;  ///< document and page, or file:line
  /// A process value that reads NaN when its input fails (Point::nan_on_input_error).
  bool nan_on_input_error = false;
};

/// The rows as a register map of unit `unit_id` (holding registers, raw values: scale 1).
drivers::modbus::RegisterMap register_map(const std::string& device, int unit_id,
                                          const std::vector<SourcePoint>& rows);

/// A temperature as a Watlow integer register holds it: deg C or deg F (F4P p. 6.11, register
/// 901), times 10^decimals (F4P p. 6.13, register 606: 0 -> "0", 1 -> "0.0" ...), rounded,
/// clipped to 16 bits signed. c_of_raw is the inverse.
double watlow_raw(double c, int decimals, bool fahrenheit);
double watlow_c_of_raw(std::int16_t raw, int decimals, bool fahrenheit);
/// deg C in the controller's unit (floats of the F4T: [CCL] __profile_units), and back; a rate
/// per unit time scales without the offset.
double watlow_unit(double c, bool fahrenheit);
double watlow_c(double unit, bool fahrenheit);
double watlow_c_delta(double unit_delta, bool fahrenheit);

/// Series F4 ([CCL] watlowf4.py; [F4P] where CCL is silent).
namespace f4 {
/// `humidity_event` (1..8; 0 none): the event output served as kHumidityEvent when it is not
/// the run event.
std::vector<SourcePoint> points(int run_event, int humidity_event = 2);
inline constexpr const char *kAir = "input1_pv", *kAirError = "input1_err", *kProduct = "input2_pv",
                            *kProductError = "input2_err", *kStatus = "status",
                            *kSetpoint = "setpoint1", *kSetpointLow = "sp_low1",
                            *kSetpointHigh = "sp_high1", *kDecimals = "decimals1",
                            *kDecimals2 = "decimals2", *kUnits = "units", *kRunEvent = "event",
                            *kInput1Units = "input1_units", *kInput2Units = "input2_units",
                            *kHumidityEvent = "humidity_event";
inline constexpr int kEventOff = 0, kEventOn = 1;                    // CCL set_event:539-543
/// What an input measures, registers 608/618 (CCL get_loop_units:392-397).
inline constexpr int kInputTemperature = 0, kInputHumidity = 1, kInputPressure = 2;
/// The event output a TestEquity humidity chamber wires to humidity ([TE] p. 51: "Event 2 is
/// Humidity in Humidity models"); the simulator serves it when the run event is another.
inline constexpr int kHumidityEventNumber = 2;
inline constexpr int kStatusConstant = 1, kStatusProfilePaused = 3;  // CCL get_status:545-554
inline constexpr int kUnitsFahrenheit = 0, kUnitsCelsius = 1;        // F4P p. 6.11
inline constexpr int kInputOverRange = 3;  // F4P p. 2.5: "SEnhi", input error 3
}  // namespace f4

/// An F4T in Data Map 2, F4 compatibility ([TE] p. 47, [TE101H] p. 61): a limited set of the F4
/// registers — no status (200), no setpoint limits (602/603), no input units (608/618); input 2
/// (104) is the chamber humidity. Not implemented on F4Ts with cascade control ([TE] p. 47, 52):
/// the simulated cascade unit answers exception 02 to every Data Map 2 register.
namespace f4t_map2 {
std::vector<SourcePoint> points(int run_event, int humidity_event = 2);
}  // namespace f4t_map2

/// F4T Data Map 1 ([CCL] watlowf4t.py, modbus.py; [TE] for the ramp registers).
namespace f4t {
/// `loop` is the air loop (1..4), `rtu` picks the units register of a serial link.
std::vector<SourcePoint> points(int run_event, bool rtu, int loop = 1, int humidity_event = 2);
inline constexpr const char *kAir = "loop1_pv", *kProduct = "loop2_pv", *kSetpoint = "loop1_sp",
                            *kWorkingSetpoint = "loop1_wsp", *kSetpointLow = "loop1_sp_min",
                            *kSetpointHigh = "loop1_sp_max", *kLoopMode = "loop1_mode",
                            *kRampAction = "loop1_ramp_action", *kRampScale = "loop1_ramp_scale",
                            *kRampRate = "loop1_ramp_rate", *kProfileState = "profile_state",
                            *kAlarm1 = "alarm1_state", *kRunEvent = "event", *kUnits = "units",
                            *kLoop1Kind = "loop1_pv_kind", *kLoop2Kind = "loop2_pv_kind",
                            *kHumidityEvent = "humidity_event";
/// What a loop's process value is (CCL __profile_units:991-1007, register 16536 + 2 (n - 1),
/// codes from the __init__ dictionary:103-112); readable with the profile option only.
inline constexpr int kAbsoluteTemperature = 1540, kRelativeTemperature = 1541, kNotSourced = 246,
                     kHumidity = 1538;
/// Part number characters (CCL process_controller:861-921): character 7 (index 6) 'D'..'F' =
/// profiles; character 12 (index 11) the loops: '1'..'4' loops, '5' none, '6'..'C' cascade.
/// Part number, one character per register from 16 (CCL process_controller:861-921).
inline constexpr int kPartNumberRegisters = 15;
std::string part_number_point(int i);
// Watlow enumeration codes (CCL watlowf4t.py __init__:78-121 and the functions named).
inline constexpr int kAuto = 10, kManual = 54;         // CCL set_loop_mode:294-309
inline constexpr int kOff = 62, kOn = 63;              // CCL set_event:508-520 (#62=off)
inline constexpr int kCelsius = 15, kFahrenheit = 30;  // CCL __profile_units:990-1007
inline constexpr int kHours = 39, kMinutes = 57;       // CCL dictionary; [TE] the register
inline constexpr int kRampSetpoint = 85;               // CCL dictionary "setpoint"
inline constexpr int kStartup = 88, kRampBoth = 13;    // CCL dictionary ("startup", "both")
inline constexpr int kProfilePaused = 146;             // CCL get_status:528-546
inline constexpr int kAlarmNone = 61;                  // CCL get_alarm_status:552 (inactive)
/// Alarm state "error": its source signal has an input error (CCL dictionary:81, 28 'error';
/// Watlow F4T Setup & Operations p. 83: a signal in error "cannot be relied on").
inline constexpr int kAlarmError = 28;
/// Event outputs 1..8 (CCL get_event:499-506).
inline constexpr int kEvents[] = {16594, 16596, 16598, 16600, 16822, 16824, 16826, 16828};
}  // namespace f4t

/// Series F4P ([F4P] chapter 9 and the parameter tables of chapter 6).
namespace f4p {
std::vector<SourcePoint> points();
inline constexpr const char *kModel = "model", *kAir = "input1_pv", *kAirError = "input1_err",
                            *kAlarm1 = "alarm1_status", *kOperation = "auto_manual",
                            *kControlSetpoint = "control_sp", *kSetpoint = "setpoint1",
                            *kSetpointLow = "sp_low1", *kSetpointHigh = "sp_high1",
                            *kDecimals = "decimals1", *kUnits = "units", *kRampMode = "ramp_mode",
                            *kRampRate = "ramp_rate", *kRampScale = "ramp_scale";
inline constexpr int kModelF4p = 5280;            // p. 6.27: "P4 (4P) ASCII 5280 Dec"
inline constexpr int kAuto = 1, kManual = 2;      // register 200, p. 9.2
inline constexpr int kRampOff = 0, kRampMax = 2;  // register 1100: off, startup, startup/change
inline constexpr int kRampRateMin = 1, kRampRateMax = 999;     // register 1101, p. 6.8
inline constexpr int kPerMinute = 0, kPerHour = 1;             // register 1102, p. 6.8
inline constexpr int kUnitsFahrenheit = 0, kUnitsCelsius = 1;  // register 901, p. 6.11
inline constexpr int kInputOverRange = 3;                      // p. 2.5
}  // namespace f4p

}  // namespace station::sim::sources
