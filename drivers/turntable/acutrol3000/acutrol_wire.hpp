// Acutronic ACUTROL3000 command language, as used for a single-axis rate table (dialect
// "acutrol3000"): command spellings, framing and reply parsers, shared by Acutrol3000Table and the
// simulator's ACUTROL face; tests/drivers/test_dialect_conformance.cpp checks them against the
// table transcribed from the sources (docs/DEVICES.md). No I/O.
//
// Sources: [ACL] Acutronic TM-8004 "Acutrol3000 Command Language Programming Manual"; [TCP]
// TM-9384C "TCP/IP Interface"; [RN] TM-9389 release notes; [py] acutrol3000.py, all in the public
// repository github.com/IEAv-EFO/acutrol3000 @3777621 (doc/, python/). Pages as printed.
// Assumptions to check on a real unit (docs/DEVICES.md): replies end in LF (as over GPIB, [py]);
// a command without data answers an empty line ([RN] p. 5); the binary error/length header that
// [ACL] p. 2 describes for non-GPIB links is NOT implemented; :Interlock? answers Close, Open or
// Fault ([ACL] p. 133 lists that enumeration, [py] :41 confirms Fault); an error answers a line
// starting "Error".
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace station::drivers::acutrol3000 {

/// TCP port of the real-time computer ([TCP] p. 1).
inline constexpr int kTcpPort = 9878;
/// Commands end in CR LF ([ACL] p. 4: CR and/or LF accepted); replies end in LF.
inline constexpr std::string_view kCommandTerminator = "\r\n";
inline constexpr std::string_view kReplyTerminator = "\n";
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
/// True for an error reply.
bool is_error(std::string_view reply);
/// Position wrapped into [0, 360) (the unit reports +-180 or 0..360 by configuration, [ACL] p.
/// 101).
double wrap_deg(double deg);

}  // namespace station::drivers::acutrol3000
