// CLI11 validators for text options, by the one text rule (common/text_rule.hpp): an operator's
// name with a newline, 100 kB of it, or a bidirectional control is refused at the edge with the
// option's name, before anything is stored.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>

namespace station {

/// Accepts a note of at most `max_bytes` bytes (common/text_rule.hpp, note_problem).
CLI::Validator note_text(std::size_t max_bytes);
/// Accepts an identifier (common/text_rule.hpp, identifier_problem).
CLI::Validator identifier_text();

}  // namespace station
