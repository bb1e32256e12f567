// The ACUTROL command-language grammar, parsed against the command tree transcribed from [ACL]
// (sim_devices/sources/acutrol_sources.hpp): program message units separated by ';' (a ';' that
// is not inside "..."), each a header and its arguments after white space ([ACL] §2 p. 2: no
// comma between them); mnemonics in any case and as any prefix of their long form (§2.1 p. 2);
// a unit without a leading ':' continues in the subsystem of the unit before it, ';:' returns to
// the root, and the first unit's colon is optional (§2.2-2.3 p. 3-4). A prefix is resolved level
// by level (`:int:close` is Interlock:Close: Interface has no Close); among what remains the
// Act2000 command wins (AclNode::act2000). No I/O.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sim_devices/sources/acutrol_sources.hpp"

namespace station::sim {

/// One program message unit, resolved.
struct AclUnit {
  std::string text;                                 ///< the unit as sent
  const sources::acutrol::AclNode* node = nullptr;  ///< the command (nullptr when not parsed)
  std::string path;                                 ///< long form, ":Mode:Position" or "*IDN"
  bool query = false;
  std::vector<std::string> args;  ///< the arguments, blanks around each removed
  /// 0 when the unit parsed; else the ACL error (SYNTAX ERROR, ILLEGAL CMD) and why.
  std::uint32_t error = 0;
  std::string why;
};

/// True when `abbreviation` is a non-empty prefix of `word`, letters compared in any case
/// ([ACL] §2.1 p. 2: mnemonics and enumerated arguments alike: `:lim:rate pos,1,...`).
bool acl_abbreviates(std::string_view abbreviation, std::string_view word);

/// The units of `message`, in order; parsing stops after the first unit that does not parse
/// (the last one returned, with its error). Empty units (a trailing ';') are skipped.
std::vector<AclUnit> parse_acl(std::string_view message);

}  // namespace station::sim
