// The one rule for text a person gives the station that ends up in a file someone else reads
// (issue 34 point 10): identifiers (serials, part numbers, station names) and free text (release
// notes, who released, the operator, a part's description). Applied where text enters (config
// and part files, CLI options, API bodies); every export format still escapes for its reader.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace station {

/// Longest identifier, bytes (a serial or part number; the C header's name mangles 64).
inline constexpr std::size_t kMaxIdentifierBytes = 64;
/// Longest name of a person (--by, --operator), bytes.
inline constexpr std::size_t kMaxPersonBytes = 200;
/// Longest label of a protocol step, bytes.
inline constexpr std::size_t kMaxLabelBytes = 200;
/// Longest note (--note, --override, a part's description), bytes.
inline constexpr std::size_t kMaxNoteBytes = 4096;

/// The characters an identifier may hold besides ASCII letters and digits.
inline constexpr std::string_view kIdentifierPunctuation = "-_.:/+#";

/// Why `text` is not an identifier (1..kMaxIdentifierBytes bytes of ASCII letters, digits and
/// kIdentifierPunctuation, starting with a letter or digit), naming the first offending
/// character as U+XXXX and its position; empty when it is one.
std::optional<std::string> identifier_problem(std::string_view text);

/// Why `text` is not a note of at most `max_bytes` bytes (valid UTF-8; no C0 control, DEL, C1
/// control, bidirectional control or line/paragraph separator), naming the first offending
/// character as U+XXXX (or the byte that is not UTF-8) and its position; empty when it is one.
std::optional<std::string> note_problem(std::string_view text, std::size_t max_bytes);

/// Throws InputError "WHERE: PROBLEM" when `text` is not an identifier.
void require_identifier(std::string_view where, std::string_view text);
/// Throws InputError "WHERE: PROBLEM" when `text` is not a note of at most `max_bytes`.
void require_note(std::string_view where, std::string_view text, std::size_t max_bytes);

/// `text` in printable ASCII whatever it holds: each character outside 0x20..0x7E as
/// "<U+XXXX>", each byte that is not UTF-8 as "<0xNN>" (for a C comment: no bidirectional
/// control or newline can reach a compiler or a reviewer's screen).
std::string ascii_escaped(std::string_view text);

/// `text` as valid UTF-8 whatever it holds: each byte that is not part of a valid sequence
/// becomes U+FFFD (for writers of text that came from an older record).
std::string valid_utf8(std::string_view text);

}  // namespace station
