// The ACUTROL3000 command language as Acutronic's manuals give it, transcribed by hand: the
// simulated ACUTROL parses and answers from these tables, and the conformance test holds the
// driver's command spellings (drivers/turntable/acutrol3000/acutrol_wire.hpp) against them.
// Nothing here comes from drivers/turntable/ (docs/DEVICES.md).
//
// [ACL] TM-8004-C "Acutrol3000 Command Language (ACL) Programming Manual"; [RT] TM-9374A "Real
// Time Data Communication Manual"; [RN] TM-9389 release notes; all in the public repository
// github.com/IEAv-EFO/acutrol3000 @3777621, doc/. Pages as printed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace station::sim::sources::acutrol {

/// How a node is used ([ACL] §2.4 p. 4: "Command?" a query, "Command[?]" both).
enum Form : unsigned {
  kCommand = 1,          ///< sent without '?'
  kQuery = 2,            ///< sent with '?'
  kQueryWithoutMark = 4  ///< a query also without '?' ("for ACT2000 compatibility", p. 168-169)
};

/// One mnemonic of the command tree ([ACL] §2.3 p. 3, §4 p. 28-197).
struct AclNode {
  std::string_view name;  ///< long form, as the manual's COMMAND/QUERY lines spell it
  int page;               ///< [ACL] page of its section (0: named only in Tables 5-7, p. 23-24)
  unsigned forms;         ///< Form bits; 0: a subsystem that is no command by itself
  /// Kept from the Act2000 ([ACL] Table 5 and 6, p. 23). ACL warns that one-letter short forms
  /// may be ambiguous (§2.1 p. 2) yet its own examples use them: `:I:C 1` is Interlock:Close
  /// (p. 131), `:I:R` Interlock:Reset (p. 136), although Interface, Interlock:Configure and
  /// Control also start so. The language keeps the Act2000's meaning (p. 1: "as backward
  /// compatible as possible"): among ambiguous matches the Act2000 command wins.
  bool act2000;
  std::span<const AclNode> children;
};

/// The main-level subsystems, in the manual's order (§4).
std::span<const AclNode> root();
/// The IEEE-488.2 common commands (§3, p. 14-21): matched whole, never abbreviated.
std::span<const AclNode> common();

// Reply framing. Non-GPIB links: "all commands issued to Acutrol will receive a response ...
// [that] includes an error code and a message length; this is prefixed to data" ([ACL] §2 p. 2);
// the layout as [RT] §3.4.2 p. 34 gives it: a 32-bit error return, a 32-bit length in characters,
// then a null-terminated string of that length; binary least significant byte first ([ACL] §2.4
// p. 4, §5.1.1 p. 206).
inline constexpr std::size_t kHeaderBytes = 8;
/// At most 32K characters of response data in one message ([ACL] §2.5 p. 5).
inline constexpr std::size_t kMaxResponseChars = 32768;
/// A bare reply's end: "ACL commands without a response now send CR/LF (except for GPIB
/// interface)" ([RN] build 1848, p. 5); <END> may carry CR and/or LF ([ACL] §2.4 p. 4).
inline constexpr std::string_view kBareEnd = "\r\n";

// The status byte ([ACL] §3.10 p. 19-20): bit 7 (EQ) summarizes the Error Message Queue, bit 6
// is MSS, bit 0 (SI) the system interlocks; "Reading the STB will clear all of the bits".
inline constexpr unsigned kStbErrorQueue = 0x80, kStbMss = 0x40, kStbInterlocks = 0x01;
/// The error message queue's id for :Status:MSG? ([ACL] p. 174).
inline constexpr std::string_view kErrorQueueId = "QERROR";

/// An ACL error. The commands name the Status Byte bit each error sets: SYNTAX ERROR, ILLEGAL
/// CMD, PARAMETER OUT OF RANGE (e.g. [ACL] p. 31, 53, 145). The numeric codes [RT] p. 34 refers
/// to ("Appendix C of TM-8004") are not in the public copy: these numbers are the simulator's.
struct AclError {
  std::uint32_t code;
  std::string_view text;
};
inline constexpr AclError kSyntaxError{1, "SYNTAX ERROR"};
inline constexpr AclError kIllegalCommand{2, "ILLEGAL CMD"};
inline constexpr AclError kParameterOutOfRange{3, "PARAMETER OUT OF RANGE"};
/// The description :Query:Error? <code> returns ([ACL] p. 163); empty for an unknown code.
std::string_view error_text(std::uint32_t code);

/// The servo modes :Mode and :Limit take and report ([ACL] §4.7 p. 147), in the manual's order.
inline constexpr std::string_view kModes[] = {"Position", "Rate",  "Arate", "Synthesis",
                                              "Track",    "Abort", "Off"};
/// *IDN?: <manufacturer>,<model>,<serial number>,<software level> ([ACL] §3.4 p. 15); the
/// simulator's own fields.
inline constexpr std::string_view kIdentity = "Acutronic,Acutrol3000 SIM,0,sim-1.0";

}  // namespace station::sim::sources::acutrol
