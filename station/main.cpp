// The `station` executable: subcommands over the station core. Setup and input errors are
// caught here and become one line on stderr and exit status 2.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <string>

#include "station/cli/commands.hpp"
#include "station/cli/csv_table.hpp"
#include "station/common/allocator.hpp"
#include "station/store/sqlite.hpp"

namespace {

/// CLI11 would say only "A subcommand is required": names the word and the known commands.
/// False (after printing so) when argv[1] is a word that is no subcommand.
bool known_subcommand(CLI::App& app, const char* word) {
  std::string known;
  bool found = false;
  for (const CLI::App* sub : app.get_subcommands({})) {
    found = found || sub->check_name(word);
    known += (known.empty() ? "" : ", ") + sub->get_name();
  }
  if (!found)
    fmt::print(stderr, "station: unknown subcommand '{}'; known: {} (see --help)\n", word, known);
  return found;
}

}  // namespace

int main(int argc, char** argv) {
  station::keep_freed_memory_for_reuse();
  // A file size limit (RLIMIT_FSIZE, `prlimit --fsize`) must not kill the daemon silently: with
  // SIGXFSZ ignored the write fails with EFBIG, SQLite reports it, and it is handled like a full
  // disk (setrlimit(2), signal(7)).
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"Gyro thermal-calibration test station"};
  app.set_version_flag("--version", std::string("station ") + STATION_VERSION);
  app.require_subcommand(1);
  // One line per error, like every other input error (CLI11's default adds a second line).
  app.failure_message([](const CLI::App* /*app*/, const CLI::Error& e) {
    return fmt::format("station: {} (see --help)\n", e.what());
  });
  station::CommandStatus status;
  station::add_analyze_command(app, status);
  station::add_adev_command(app, status);
  station::add_probe_command(app, status);
  station::add_run_command(app, status);
  station::add_serve_command(app, status);
  station::add_fit_commands(app, status);
  station::add_release_commands(app, status);
  station::add_history_command(app, status);
  station::add_sync_command(app, status);
  station::add_fleet_command(app, status);
  station::add_replay_command(app, status);
  station::add_report_command(app, status);
  if (argc > 1 && argv[1][0] != '-' && !known_subcommand(app, argv[1])) return 2;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  } catch (const std::exception& e) {
    // Bad input, and a storage fault (it names the database file: the user's file to look at,
    // like bad input), exit 2; anything else is unexpected.
    if (dynamic_cast<const station::SqliteError*>(&e) != nullptr ||
        dynamic_cast<const station::InputError*>(&e) != nullptr ||
        dynamic_cast<const std::invalid_argument*>(&e) != nullptr) {
      fmt::print(stderr, "station: {}\n", e.what());
      return 2;
    }
    fmt::print(stderr, "station: error: {}\n", e.what());
    return 1;
  }
  return status.exit_code;
}
