// parse_acl: message units, headers resolved in the transcribed tree, arguments split.
#include "sim_devices/faces/acl_parser.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <optional>
#include <span>

namespace station::sim {
namespace {

bool same_letters(std::string_view a, std::string_view b);

namespace src = sources::acutrol;
using Nodes = std::span<const src::AclNode>;

// A node reached by a header, and the subsystem it sits in (empty: the root).
struct Match {
  const src::AclNode* node;
  Nodes siblings;
  std::string path;
};

bool same_letters(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) !=
        std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// Units split at ';' outside "..." ([ACL] p. 4: '"' delimits a string).
std::vector<std::string_view> split_units(std::string_view message) {
  std::vector<std::string_view> out;
  bool quoted = false;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= message.size(); ++i) {
    if (i < message.size() && message[i] == '"') quoted = !quoted;
    if (i == message.size() || (message[i] == ';' && !quoted)) {
      out.push_back(message.substr(start, i - start));
      start = i + 1;
    }
  }
  return out;
}

std::vector<std::string> split_args(std::string_view args) {
  std::vector<std::string> out;
  if (trim(args).empty()) return out;
  bool quoted = false;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= args.size(); ++i) {
    if (i < args.size() && args[i] == '"') quoted = !quoted;
    if (i == args.size() || (args[i] == ',' && !quoted)) {
      out.emplace_back(trim(args.substr(start, i - start)));
      start = i + 1;
    }
  }
  return out;
}

// The children of `from` whose long form `mnemonic` begins (case-insensitive); a full match
// takes precedence over prefixes.
std::vector<Match> step(const std::vector<Match>& from, std::string_view mnemonic) {
  std::vector<Match> prefix, exact;
  for (const Match& m : from) {
    const Nodes children = m.node ? m.node->children : m.siblings;
    for (const auto& c : children) {
      if (!acl_abbreviates(mnemonic, c.name)) continue;
      Match next{&c, children, m.path + ":" + std::string(c.name)};
      (c.name.size() == mnemonic.size() ? exact : prefix).push_back(std::move(next));
    }
  }
  return exact.empty() ? prefix : exact;
}

bool takes(const src::AclNode& n, bool query) {
  return query ? (n.forms & src::kQuery) != 0
               : (n.forms & (src::kCommand | src::kQueryWithoutMark)) != 0;
}

// Resolves `mnemonics` below `base`; sets the unit's node and path and returns the match, or
// sets the unit's error.
std::optional<Match> resolve(AclUnit& u, const Match& base,
                             const std::vector<std::string_view>& mnemonics) {
  std::vector<Match> level{base};
  for (std::string_view m : mnemonics) {
    level = step(level, m);
    if (level.empty()) {
      u.error = src::kSyntaxError.code;
      u.why = fmt::format("'{}' names no command here", m);
      return std::nullopt;
    }
  }
  std::optional<Match> pick;
  for (const Match& m : level)  // the Act2000 command first, then the manual's order
    if (takes(*m.node, u.query) && (!pick || (m.node->act2000 && !pick->node->act2000))) pick = m;
  if (!pick) {
    // A form the command lacks ([ACL] p. 32: a query of a command sets ILLEGAL CMD).
    u.error = level.front().node->forms == 0 ? src::kSyntaxError.code : src::kIllegalCommand.code;
    u.path = level.front().path;
    u.why = u.query ? "has no query form" : "is no command by itself";
    return std::nullopt;
  }
  u.node = pick->node;
  u.path = pick->path;
  u.query = u.query || (pick->node->forms & src::kCommand) == 0;  // a Read query without '?'
  return pick;
}

// A common command: the whole word, any case (§3).
void resolve_common(AclUnit& u, std::string_view header) {
  for (const auto& c : src::common()) {
    if (!same_letters(c.name, header)) continue;
    u.path = std::string(c.name);
    if (!takes(c, u.query)) {
      u.error = src::kIllegalCommand.code;
      u.why = u.query ? "has no query form" : "is a query only";
      return;
    }
    u.node = &c;
    return;
  }
  u.error = src::kSyntaxError.code;
  u.why = fmt::format("'{}' is no common command", header);
}

// One unit; `location` is the subsystem a unit without a leading ':' continues in.
AclUnit parse_unit(std::string_view text, bool first, Match& location) {
  AclUnit u;
  text = trim(text);
  u.text = std::string(text);
  const auto blank = text.find_first_of(" \t");
  std::string_view header = text.substr(0, blank);
  u.args = split_args(blank == std::string_view::npos ? "" : text.substr(blank + 1));
  u.query = !header.empty() && header.back() == '?';
  if (u.query) header.remove_suffix(1);
  if (!header.empty() && header.front() == '*') {
    resolve_common(u, header);
    return u;
  }
  const bool rooted = first || (!header.empty() && header.front() == ':');
  if (!header.empty() && header.front() == ':') header.remove_prefix(1);
  std::vector<std::string_view> mnemonics;
  for (std::size_t start = 0;;) {
    const auto colon = header.find(':', start);
    mnemonics.push_back(header.substr(start, colon - start));
    if (colon == std::string_view::npos) break;
    start = colon + 1;
  }
  for (std::string_view m : mnemonics) {
    const bool word = !m.empty() && std::all_of(m.begin(), m.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) != 0;
    });
    if (!word) {
      u.error = src::kSyntaxError.code;
      u.why = fmt::format("header '{}' is not mnemonics joined by ':'", header);
      return u;
    }
  }
  const auto found = resolve(u, rooted ? Match{nullptr, src::root(), ""} : location, mnemonics);
  // The parser stays in the subsystem of the last mnemonic (§2.3 p. 3).
  if (found) location = Match{nullptr, found->siblings, u.path.substr(0, u.path.rfind(':'))};
  return u;
}

}  // namespace

bool acl_abbreviates(std::string_view abbreviation, std::string_view word) {
  return !abbreviation.empty() && abbreviation.size() <= word.size() &&
         same_letters(word.substr(0, abbreviation.size()), abbreviation);
}

std::vector<AclUnit> parse_acl(std::string_view message) {
  std::vector<AclUnit> out;
  Match location{nullptr, src::root(), ""};
  for (std::string_view text : split_units(message)) {
    if (trim(text).empty()) continue;
    out.push_back(parse_unit(text, out.empty(), location));
    if (out.back().error != 0) break;
  }
  return out;
}

}  // namespace station::sim
