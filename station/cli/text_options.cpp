// Text option validators: the text rule's problem is CLI11's error ("--operator: U+000A ...").
#include "station/cli/text_options.hpp"

#include <fmt/format.h>

#include "station/common/text_rule.hpp"

namespace station {

CLI::Validator note_text(std::size_t max_bytes) {
  return CLI::Validator(
      [max_bytes](std::string& s) -> std::string {
        return note_problem(s, max_bytes).value_or("");
      },
      fmt::format("TEXT (at most {} bytes)", max_bytes));
}

CLI::Validator identifier_text() {
  return CLI::Validator(
      [](std::string& s) -> std::string { return identifier_problem(s).value_or(""); }, "ID");
}

}  // namespace station
