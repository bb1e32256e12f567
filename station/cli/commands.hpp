// Subcommand registration for the `station` executable: each adds itself to the CLI11 app and
// stores its exit status in the shared slot when it runs.
#pragma once

#include <CLI/CLI.hpp>

namespace station {

/// Exit status of the subcommand that ran (0 ok, 2 bad input, 1 run failure).
struct CommandStatus {
  int exit_code = 0;
};

/// `station analyze FILE.csv ...`: bin, fit and evaluate the thermal bias model offline.
void add_analyze_command(CLI::App& app, CommandStatus& status);
/// `station adev FILE.csv --col NAME ...`: overlapping Allan deviation and noise terms.
void add_adev_command(CLI::App& app, CommandStatus& status);
/// `station probe --config FILE [--json]`: read every configured device once (commissioning).
void add_probe_command(CLI::App& app, CommandStatus& status);
/// `station run`: run a protocol on a rig (--sim: the embedded simulated rig).
void add_run_command(CLI::App& app, CommandStatus& status);
/// `station serve --config FILE --db DB [--http ADDR]`: the long-running service.
void add_serve_command(CLI::App& app, CommandStatus& status);
/// `station fit`: per-serial fits from the database (--cv: leave-one-run-out).
void add_fit_commands(CLI::App& app, CommandStatus& status);
/// `station release`, `station export`, `station verify`: delivering a calibration.
void add_release_commands(CLI::App& app, CommandStatus& status);
/// `station history --db DB --serial SN [--json]`: one gyro's runs, fits, scatter and drift.
void add_history_command(CLI::App& app, CommandStatus& status);
/// `station sync --db DB --pg URL [--init]`: forward the record to the fleet's PostgreSQL once.
void add_sync_command(CLI::App& app, CommandStatus& status);
/// `station fleet --pg URL [--part PN] [--out DIR]`: control charts across the fleet.
void add_fleet_command(CLI::App& app, CommandStatus& status);
/// `station replay LOG --db PATH --run ID`: a recorded session through the driver again.
void add_replay_command(CLI::App& app, CommandStatus& status);
/// `station report --db DB --run ID --out DIR [--pdf]`: a run's report as HTML pages.
void add_report_command(CLI::App& app, CommandStatus& status);

}  // namespace station
