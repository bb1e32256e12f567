// The text rule: a small UTF-8 decoder (RFC 3629: no overlong form, no surrogate, at most
// U+10FFFF) and the two classes of text, identifiers and notes.
#include "station/common/text_rule.hpp"

#include <fmt/format.h>

#include <cstdint>

#include "station/common/input_error.hpp"

namespace station {
namespace {

/// One decoded character: its code point and length in bytes; len 0 when the bytes at the
/// position are not UTF-8.
struct Decoded {
  std::uint32_t cp = 0;
  std::size_t len = 0;
};

/// The character at byte `at` of `s` (RFC 3629 section 4's table of well-formed sequences).
Decoded decode(std::string_view s, std::size_t at) {
  const auto b0 = static_cast<unsigned char>(s[at]);
  if (b0 < 0x80) return {b0, 1};
  std::size_t len = 0;
  std::uint32_t cp = 0, min = 0;
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    len = 2, cp = b0 & 0x1Fu, min = 0x80;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    len = 3, cp = b0 & 0x0Fu, min = 0x800;
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    len = 4, cp = b0 & 0x07u, min = 0x10000;
  } else {
    return {};
  }
  if (at + len > s.size()) return {};
  for (std::size_t k = 1; k < len; ++k) {
    const auto b = static_cast<unsigned char>(s[at + k]);
    if ((b & 0xC0u) != 0x80u) return {};
    cp = (cp << 6) | (b & 0x3Fu);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return {};
  return {cp, len};
}

/// What kind of character a note may not hold; empty when it may hold `cp`.
const char* forbidden_in_note(std::uint32_t cp) {
  if (cp < 0x20 || cp == 0x7F) return "a control character";
  if (cp >= 0x80 && cp <= 0x9F) return "a C1 control character";
  // Unicode's bidirectional formatting characters (UAX #9, table 1; CVE-2021-42574).
  if ((cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069) || cp == 0x200E ||
      cp == 0x200F || cp == 0x061C)
    return "a bidirectional control";
  if (cp == 0x2028 || cp == 0x2029) return "a line or paragraph separator";
  return nullptr;
}

std::string at_text(std::uint32_t cp, std::size_t chars, std::size_t bytes) {
  return fmt::format("U+{:04X} at character {} (byte {})", cp, chars + 1, bytes);
}

bool identifier_char(std::uint32_t cp, bool first) {
  const bool alnum =
      (cp >= '0' && cp <= '9') || (cp >= 'A' && cp <= 'Z') || (cp >= 'a' && cp <= 'z');
  if (alnum) return true;
  return !first && cp < 0x80 &&
         kIdentifierPunctuation.find(static_cast<char>(cp)) != std::string_view::npos;
}

}  // namespace

std::optional<std::string> identifier_problem(std::string_view text) {
  const std::string rule = fmt::format(
      "an identifier is 1..{} ASCII letters, digits and '{}', starting with a letter or digit",
      kMaxIdentifierBytes, kIdentifierPunctuation);
  if (text.empty()) return fmt::format("empty: {}", rule);
  if (text.size() > kMaxIdentifierBytes) return fmt::format("{} bytes: {}", text.size(), rule);
  std::size_t chars = 0;
  for (std::size_t at = 0; at < text.size(); ++chars) {
    const Decoded d = decode(text, at);
    if (d.len == 0)
      return fmt::format("byte 0x{:02X} at byte {} is not UTF-8: {}",
                         static_cast<unsigned char>(text[at]), at, rule);
    if (!identifier_char(d.cp, at == 0))
      return fmt::format("{} not allowed: {}", at_text(d.cp, chars, at), rule);
    at += d.len;
  }
  return std::nullopt;
}

std::optional<std::string> note_problem(std::string_view text, std::size_t max_bytes) {
  if (text.size() > max_bytes) return fmt::format("{} bytes, at most {}", text.size(), max_bytes);
  std::size_t chars = 0;
  for (std::size_t at = 0; at < text.size(); ++chars) {
    const Decoded d = decode(text, at);
    if (d.len == 0)
      return fmt::format("byte 0x{:02X} at byte {} is not UTF-8",
                         static_cast<unsigned char>(text[at]), at);
    if (const char* what = forbidden_in_note(d.cp))
      return fmt::format("{} is {}, not allowed in text", at_text(d.cp, chars, at), what);
    at += d.len;
  }
  return std::nullopt;
}

void require_identifier(std::string_view where, std::string_view text) {
  if (const auto p = identifier_problem(text)) throw InputError(fmt::format("{}: {}", where, *p));
}

void require_note(std::string_view where, std::string_view text, std::size_t max_bytes) {
  if (const auto p = note_problem(text, max_bytes))
    throw InputError(fmt::format("{}: {}", where, *p));
}

std::string ascii_escaped(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t at = 0; at < text.size();) {
    const Decoded d = decode(text, at);
    if (d.len == 0) {
      out += fmt::format("<0x{:02X}>", static_cast<unsigned char>(text[at]));
      ++at;
      continue;
    }
    if (d.cp >= 0x20 && d.cp < 0x7F)
      out += static_cast<char>(d.cp);
    else
      out += fmt::format("<U+{:04X}>", d.cp);
    at += d.len;
  }
  return out;
}

std::string valid_utf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t at = 0; at < text.size();) {
    const Decoded d = decode(text, at);
    if (d.len == 0) {
      out += "\xEF\xBF\xBD";
      ++at;
    } else {
      out.append(text.substr(at, d.len));
      at += d.len;
    }
  }
  return out;
}

}  // namespace station
