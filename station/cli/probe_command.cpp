// `station probe`: the commissioning check of a rig (daemon/rig_probe), as a subcommand.
#include <iostream>
#include <memory>

#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/daemon/rig_probe.hpp"

namespace station {

void add_probe_command(CLI::App& app, CommandStatus& status) {
  struct Options {
    std::string config;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("probe", "Read every configured device once (commissioning)");
  cmd->footer(exit_status_footer({{0, "every configured device answered"},
                                  {1, "a device did not answer (named in the report)"}}));
  cmd->add_option("--config", o->config, "station configuration file (TOML)")->required();
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->callback([o, &status] {
    const StationConfig config = load_station_config(o->config);
    status.exit_code = probe_rig(config, RigOptions{}, std::cout, o->json);
  });
}

}  // namespace station
