// The exit statuses of `station` (main.cpp and the subcommands) and the "Exit status:" part of
// each subcommand's --help, from which its manual page's EXIT STATUS section is made (help2man,
// CMakeLists.txt): the page says what the code returns.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

namespace station {

inline constexpr int kExitOk = 0;
/// The command did its work and the result is a failure (a fit skipped, a verdict failed, a
/// replay differs, a device unreachable), or an unexpected error ("station: error: …").
inline constexpr int kExitFailure = 1;
/// Bad input or setup: configuration, protocol, options, files, a database or device in use
/// (main.cpp: one line on stderr).
inline constexpr int kExitInput = 2;
/// `serve` on SIGUSR1: everything committed, a running run left resumable, restart me.
inline constexpr int kExitRestart = 75;

/// The --help footer of a subcommand: "Exit status:" and one line per status, the command's
/// own first, then, unless the command gave its own, 2 (bad input or setup) and 1 (an
/// unexpected error).
std::string exit_status_footer(std::initializer_list<std::pair<int, std::string_view>> own);

}  // namespace station
