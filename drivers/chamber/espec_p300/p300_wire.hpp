// ESPEC P300 (and SCP-220) ASCII command protocol (dialect "espec_p300"): command spellings,
// framing and reply parsers, shared by EspecP300Chamber and the simulator's P300 face;
// tests/drivers/test_dialect_conformance.cpp checks them against the table transcribed from
// the source (docs/DEVICES.md). No I/O.
//
// Source: [CCL] ESPEC North America ChamberConnectLibrary (MIT) @1d2deb8,
// chamberconnectlibrary/p300.py and especinteract.py (functions and lines cited below).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace station::drivers::espec_p300 {

/// TCP port of the P300's LAN interface (CCL especinteract.py EspecTCP.__init__:117-121).
inline constexpr int kTcpPort = 10001;
/// Commands and replies end in CR LF (CCL EspecSerial.__init__:55, interact:97-109).
inline constexpr std::string_view kTerminator = "\r\n";
/// An error reply starts with "NA:" followed by the message (CCL EspecSerial.interact:103-108).
inline constexpr std::string_view kErrorPrefix = "NA:";

inline constexpr std::string_view kTempQuery = "TEMP?";             // CCL p300.py read_temp:358-376
inline constexpr std::string_view kMonitorQuery = "MON?";           // CCL read_mon:341-356
inline constexpr std::string_view kModeQuery = "MODE?";             // CCL read_mode:327-339
inline constexpr std::string_view kAlarmQuery = "ALARM?";           // CCL read_alarm:285-293
inline constexpr std::string_view kProductQuery = "TEMP PTC?";      // CCL read_temp_ptc:689-709
inline constexpr std::string_view kRomQuery = "ROM?";               // CCL read_rom:83-92
inline constexpr std::string_view kModeConstant = "MODE,CONSTANT";  // CCL write_mode_constant:1148
inline constexpr std::string_view kModeStandby = "MODE,STANDBY";    // CCL write_mode_standby:1142
inline constexpr std::string_view kModeOff = "MODE,OFF";            // CCL write_mode_off:1136
inline constexpr std::string_view kPowerOn = "POWER,ON";            // CCL write_power:1014-1021

/// `TEMP, S<sp>` with one decimal, comma + space (CCL write_temp:1037-1038).
std::string temp_setpoint_command(double setpoint_c);
/// The request as sent on a serial RS-485 line: "<address>,<command>" when address > 0 (CCL
/// EspecSerial.interact:93-96); TCP ignores the address (EspecTCP.interact:148-153).
std::string addressed(std::string_view command, int address);
/// True for an error reply; `message` gets the text after "NA:".
bool is_error(std::string_view reply, std::string* message = nullptr);

/// TEMP? reply "pv,sp,high,low" (CCL read_temp:358-376: high/low the controller's limits).
struct TempReply {
  double pv_c = 0, sp_c = 0, high_c = 0, low_c = 0;
};
std::optional<TempReply> parse_temp(std::string_view reply);

/// MON? reply "temp,humi,mode,alarms"; humi empty without humidity (CCL read_mon:341-356).
struct MonReply {
  double temp_c = 0;
  std::string mode;  ///< OFF, STANDBY, CONSTANT, RUN (RUN PAUSE ... with DETAIL)
  int alarms = 0;    ///< number of active alarms
};
std::optional<MonReply> parse_mon(std::string_view reply);

/// ALARM? reply: field 0 skipped (a count), then the active alarm codes (CCL read_alarm:285-293).
std::optional<std::vector<int>> parse_alarm(std::string_view reply);

/// TEMP PTC? reply, 7 fields: ON/OFF, product PV, air PV, air SP, product SP, +dev, -dev (CCL
/// read_temp_ptc:689-709). The product temperature is field 1.
std::optional<double> parse_product(std::string_view reply);

/// The modes MODE? returns (CCL read_mode:327-339).
enum class Mode { off, standby, constant, run, unknown };
Mode parse_mode(std::string_view word);

}  // namespace station::drivers::espec_p300
