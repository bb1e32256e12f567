// `station probe`: the commissioning check of a rig (daemon/rig_probe), as a subcommand. It takes
// the rig's device locks first, as `run` and `serve` do: while another station process holds
// them, probe touches no device (a SYNC on a running rig's bus would be answered to both) and
// asks that process what it sees instead (probe_in_use.hpp); --force refuses then.
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/cli/probe_in_use.hpp"
#include "station/daemon/daemon_setup.hpp"
#include "station/daemon/rig_probe.hpp"

namespace station {
namespace {

struct ProbeOptions {
  std::string config, http;
  bool json = false, force = false;
};

int run_probe(const ProbeOptions& o) {
  const StationConfig config = load_station_config(o.config);
  std::vector<ProcessLock> locks;
  try {
    locks = lock_devices(config);  // held while probing: no run starts on a rig being probed
  } catch (const LockHeld& held) {
    if (o.force)
      throw InputError(
          fmt::format("probe --force: {}; refusing to touch a rig in use (stop that "
                      "process first, or probe without --force to ask it)",
                      held.what()));
    const auto answer = http::fetch_status(o.http.empty() ? config.http.listen : o.http, 2.0);
    return print_daemon_view(held.what(), held.holder_pid(), answer, std::cout, o.json);
  }
  return probe_rig(config, RigOptions{}, std::cout, o.json);
}

}  // namespace

void add_probe_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<ProbeOptions>();
  auto* cmd = app.add_subcommand(
      "probe",
      "Read every configured device once (commissioning); while a station process runs the rig, "
      "ask it what it sees instead and touch no device");
  cmd->footer(exit_status_footer(
      {{0,
        "every configured device answered (or, rig in use, every device the running station "
        "reads)"},
       {1, "a device did not answer (named in the report)"},
       {2,
        "bad configuration, or the rig is in use and no station answered at --http (or "
        "--force was given)"}}));
  cmd->add_option("--config", o->config, "station configuration file (TOML)")->required();
  cmd->add_option("--http", o->http,
                  "where the running station serves its API when the rig is in use (HOST:PORT; "
                  "default [http] listen, else 127.0.0.1:8080)");
  cmd->add_flag("--force", o->force,
                "read the devices themselves; refused while another station process holds them");
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->callback([o, &status] { status.exit_code = run_probe(*o); });
}

}  // namespace station
