// The "Exit status:" footer of a subcommand's --help (see exit_status.hpp).
#include "station/cli/exit_status.hpp"

#include <fmt/format.h>

namespace station {

std::string exit_status_footer(std::initializer_list<std::pair<int, std::string_view>> own) {
  std::string out = "Exit status:\n";
  bool failure = false, input = false;
  for (const auto& [code, meaning] : own) {
    out += fmt::format("  {:<4}{}\n", code, meaning);
    failure = failure || code == kExitFailure;
    input = input || code == kExitInput;
  }
  if (!input)
    out += fmt::format(
        "  {:<4}bad input or setup: options, configuration, protocol or file, a database or "
        "device in use (one line on stderr)\n",
        kExitInput);
  if (!failure)
    out += fmt::format("  {:<4}an unexpected error (\"station: error: ...\")\n", kExitFailure);
  return out;
}

}  // namespace station
