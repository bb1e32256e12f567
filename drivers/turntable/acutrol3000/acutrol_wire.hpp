// Acutronic ACUTROL3000 command language, as used for a single-axis rate table (dialect
// "acutrol3000"): command spellings, reply framing and parsers for Acutrol3000Table;
// tests/drivers/test_dialect_conformance.cpp checks them against the simulator's own
// transcription of the sources (sim_devices/sources/acutrol_sources.hpp) and docs/DEVICES.md
// lists them. No I/O.
//
// Sources: [ACL] Acutronic TM-8004-C "Acutrol3000 Command Language Programming Manual"; [RT]
// TM-9374A "Real Time Data Communication Manual"; [TCP] TM-9384C "TCP/IP Interface"; [RN]
// TM-9389 release notes; [py] python/acutrol3000.py, all in the public repository
// github.com/IEAv-EFO/acutrol3000 @3777621 (doc/, python/). Pages as printed.
// Reply framing ([ACL] §2 p. 2): on non-GPIB links every command gets a response that "includes
// an error code and a message length; this is prefixed to data"; [RT] §3.4.2 p. 34 spells the
// layout out (a 32-bit error return, a 32-bit length in characters, a NUL-terminated string),
// binary data least significant byte first ([ACL] §2.4 p. 4). Whether the TCP port sends that
// header or bare lines (GPIB-like, [py]; [RN] p. 5: "ACL commands without a response now send
// CR/LF") no public document settles: `framing` picks one or recognizes it at connect.
// Errors are read as ACL reports them: the header's error code, or on bare lines the status
// byte's error-queue bit (*STB?, [ACL] p. 19-20) and the queue's message (:Status:MSG? QERROR,
// p. 174, 178). Assumptions to check on a real unit (docs/DEVICES.md): :Interlock? answers
// Close, Open or Fault ([ACL] p. 133 lists that enumeration, [py] :41 confirms Fault).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "drivers/ascii/line_client.hpp"

namespace station::drivers::acutrol3000 {

/// TCP port of the real-time computer ([TCP] p. 1).
inline constexpr int kTcpPort = 9878;
/// Commands end in CR LF ([ACL] p. 4: CR and/or LF accepted); bare replies end in LF, a CR
/// before it is dropped ([RN] p. 5: CR/LF).
inline constexpr std::string_view kCommandTerminator = "\r\n";
inline constexpr std::string_view kReplyTerminator = "\n";

/// How the unit frames its replies ([turntable] framing): recognized at connect from the reply
/// to *IDN? (a header holds NUL bytes, text never does), bare lines, or the error/length header.
enum class Framing { automatic, bare, header };
/// The names the configuration takes, as the dialect row lists them.
inline constexpr std::string_view kFramingNames = "auto,bare,header";
/// "auto" / "bare" / "header"; nullopt for any other name.
std::optional<Framing> framing_from_name(std::string_view name);
const char* to_string(Framing f);
/// The header: error return (uint32 LE) then length in characters (uint32 LE), then the string
/// and its NUL ([RT] p. 34, [ACL] p. 4); at most 32768 characters of response ([ACL] §2.5 p. 5).
inline constexpr ascii::FrameLayout kFrame{8, 4, 32768};
/// The error return of a frame's header: 0 for success ([RT] p. 34).
std::uint32_t frame_error_code(std::string_view header);

// Reading an error the ACL way ([ACL] p. 14, 19-20, 163, 174, 178).
inline constexpr std::string_view kClearStatus = "*CLS";       // [ACL] p. 14: queues too
inline constexpr std::string_view kStatusByteQuery = "*STB?";  // [ACL] p. 19-20 (clears it)
inline constexpr unsigned kErrorQueueBit = 0x80;               // bit 7 (EQ), [ACL] p. 20
inline constexpr std::string_view kErrorQueueRead = ":Status:MSG? QERROR";  // p. 178, qid p. 174
/// `:Query:Error? <code>`: the description of an error code ([ACL] p. 163).
std::string error_text_query(std::uint32_t code);
/// The status byte, NR1 0..255 ([ACL] p. 19); nullopt otherwise.
std::optional<unsigned> parse_status_byte(std::string_view reply);
/// The station's axis.
inline constexpr int kAxis = 1;

// Long forms as [ACL] spells them; the unit matches any unique prefix, case-insensitive (p. 2).
inline constexpr std::string_view kIdentify = "*IDN?";                 // [ACL] p. 15
inline constexpr std::string_view kModeOff = ":Mode:Off 1";            // [ACL] p. 150
inline constexpr std::string_view kModePosition = ":Mode:Position 1";  // [ACL] p. 151
inline constexpr std::string_view kModeRate = ":Mode:Rate 1";          // [ACL] p. 152
inline constexpr std::string_view kModeQuery = ":Mode? 1";             // [ACL] p. 147
inline constexpr std::string_view kReadPositionRate =
    ":Read:Position? 1;Rate? 1";  // [ACL] p. 168-169, [py] 14-18
inline constexpr std::string_view kInterlockQuery = ":Interlock? 1";       // [ACL] p. 24, 133
inline constexpr std::string_view kInterlockClose = ":Interlock:Close 1";  // [ACL] p. 131
inline constexpr std::string_view kInterlockReset = ":Interlock:Reset";  // [ACL] p. 136 (all axes)
inline constexpr std::string_view kRateLimitQuery = ":Limit:Rate? R,1";  // [ACL] p. 145
inline constexpr std::string_view kPositionDemandQuery = ":Demand:Position? 1";  // [ACL] p. 112
inline constexpr std::string_view kRateDemandQuery = ":Demand:Rate? 1";          // [ACL] p. 113

/// `:Demand:Position 1,<deg>` ([ACL] p. 112) and `:Demand:Rate 1,<deg/s>` ([ACL] p. 113), fixed
/// point with 5 decimals (NRf input, at most 28 characters: [ACL] p. 6-7).
std::string position_demand(double deg);
std::string rate_demand(double dps);

/// Servo modes the unit reports ([ACL] p. 147: a letter; [py] :121,148: the word).
enum class Mode { off, position, rate, other, unknown };
Mode parse_mode(std::string_view reply);
/// Interlock state (see the file comment).
enum class Interlock { closed, open, fault, unknown };
Interlock parse_interlock(std::string_view reply);
/// An NR2 number ([ACL] p. 7: fixed point, no exponent, optional sign), the whole reply.
std::optional<double> parse_number(std::string_view reply);
/// The reply to kReadPositionRate: "<pos>;<rate>" ([ACL] p. 168: several replies ';'-separated).
std::optional<std::pair<double, double>> parse_position_rate(std::string_view reply);
/// Position wrapped into [0, 360) (the unit reports +-180 or 0..360 by configuration, [ACL] p.
/// 101).
double wrap_deg(double deg);

}  // namespace station::drivers::acutrol3000
