// The ESPEC P300's command spellings as ESPEC's own client library sends them, transcribed by
// hand: the simulated P300 answers these, and the conformance test holds the driver's wire
// definition (drivers/chamber/espec_p300/p300_wire.hpp) against them. Nothing here comes from
// drivers/ (docs/DEVICES.md).
//
// [CCL] ESPEC North America ChamberConnectLibrary (MIT) @1d2deb8, chamberconnectlibrary/p300.py
// and especinteract.py.
#pragma once

#include <string_view>

namespace station::sim::sources::p300 {

inline constexpr std::string_view kTempQuery = "TEMP?";             // p300.py read_temp:358
inline constexpr std::string_view kMonitorQuery = "MON?";           // read_mon:341
inline constexpr std::string_view kModeQuery = "MODE?";             // read_mode:327
inline constexpr std::string_view kAlarmQuery = "ALARM?";           // read_alarm:285
inline constexpr std::string_view kProductQuery = "TEMP PTC?";      // read_temp_ptc:689
inline constexpr std::string_view kRomQuery = "ROM?";               // read_rom:83
inline constexpr std::string_view kModeConstant = "MODE,CONSTANT";  // write_mode_constant:1148
inline constexpr std::string_view kModeStandby = "MODE,STANDBY";    // write_mode_standby:1142
inline constexpr std::string_view kModeOff = "MODE,OFF";            // write_mode_off:1136
inline constexpr std::string_view kPowerOn = "POWER,ON";            // write_power:1014
inline constexpr std::string_view kPowerOff = "POWER,OFF";          // write_power:1014
inline constexpr std::string_view kTempSetPrefix = "TEMP, S";  // write_temp:1037 "TEMP, S%0.1f"
inline constexpr std::string_view kError = "NA:";              // especinteract.py interact:103
// The simulator acknowledges a write with "OK:<command>"; CCL looks only for kError.
inline constexpr std::string_view kOk = "OK:";

}  // namespace station::sim::sources::p300
