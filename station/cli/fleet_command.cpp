// `station fleet --pg URL [--part PN] [--since DATE] [--out DIR] [--json] [--propose-noise]`:
// control charts of the calibrations every station forwarded (station/fleet/fleet_charts.hpp) and
// of the acceptance scale factor and its temperature coefficient per part
// (station/fleet/fleet_acceptance.hpp: JSON "acceptance"), as JSON and as a self-contained page
// DIR/fleet.html; the points beyond a limit, and the results without K or TC and why, are listed.
// With --propose-noise, each part's noise from its runs (station/fleet/noise_proposal.hpp) as a
// ready-to-paste [part."PN".noise] block, in the JSON ("noise") and on the page. Read-only.
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>

#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/common/input_error.hpp"
#include "station/config/fleet_config.hpp"
#include "station/fleet/fleet_acceptance.hpp"
#include "station/fleet/fleet_charts.hpp"
#include "station/fleet/fleet_noise.hpp"
#include "station/fleet/fleet_page.hpp"

namespace station {
namespace {

struct FleetOptions {
  std::string pg, part, since, out;
  bool json = false;
  bool propose_noise = false;
};

std::string filter_text(const FleetOptions& o) {
  return fmt::format("part {}, calibrations since {}", o.part.empty() ? "any" : o.part,
                     o.since.empty() ? "the first" : o.since);
}

void print_outside(const nlohmann::json& charts) {
  for (const auto& part : charts["parts"]) {
    fmt::print("{}: {} calibrations at {} stations, {} points beyond a limit\n",
               fleet::chart_set_title(part), part["calibrations"].get<int>(),
               part["stations"].size(), part["outside"].size());
    for (const auto& o : part["outside"])
      fmt::print("  {} {} {} fit {} ({}): {:.4g} beyond the {} {}\n",
                 o["metric"].get<std::string>(), o["station"].get<std::string>(),
                 o["serial"].get<std::string>(), o["fleet_id"].get<long long>(),
                 o["created_utc"].get<std::string>(), o["value"].get<double>(),
                 o["chart"].get<std::string>(), o["limit"].get<std::string>());
  }
}

void run_fleet(const FleetOptions& o) {
  if (auto why = pg_url_problem(o.pg)) throw InputError(fmt::format("--pg: {}", *why));
  fleet::ChartFilter f;
  if (!o.part.empty()) f.part = o.part;
  if (!o.since.empty()) {
    // Compared as text with the stored ISO-8601 UTC times: only that form sorts right.
    if (!std::regex_match(o.since, std::regex(R"(\d{4}-\d{2}-\d{2}(T\d{2}:\d{2}(:\d{2})?Z?)?)")))
      throw InputError(
          fmt::format("--since '{}': not an ISO-8601 date (YYYY-MM-DD[THH:MM[:SS]Z])", o.since));
    f.since = o.since;
  }
  const report::Assets assets =
      o.out.empty() ? report::Assets{} : report::read_dygraphs(std::string(report::kDygraphsDir));
  fleet::PgConnection pg({o.pg, {}});
  auto charts = fleet::fleet_charts_json(fleet::fleet_points(pg, f));
  charts["acceptance"] = fleet::fleet_acceptance_charts(pg, f);
  std::vector<fleet::NoiseProposal> noise;
  if (o.propose_noise) {
    noise = fleet::propose_noise(fleet::fleet_run_noise(pg, f));
    charts["noise"] = nlohmann::json::array();
    for (const auto& p : noise) charts["noise"].push_back(fleet::noise_proposal_json(p));
  }
  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    const auto path = std::filesystem::path(o.out) / "fleet.html";
    std::ofstream(path) << fleet::fleet_html(charts, filter_text(o), assets);
    fmt::print(stderr, "wrote {}\n", path.string());
  }
  if (o.json) {
    std::cout << charts.dump(2) << '\n';
    return;
  }
  if (f.part && charts["parts"].empty() && charts["acceptance"]["parts"].empty())
    fmt::print("no calibration and no acceptance result of part '{}'{} in the fleet database\n",
               *f.part, f.since ? " since " + *f.since : "");
  print_outside(charts);
  fmt::print("{}", fleet::fleet_acceptance_text(charts["acceptance"]));
  for (const auto& p : noise) fmt::print("\n{}", fleet::noise_toml(p));
  if (o.propose_noise && noise.empty())
    fmt::print("\nno part's noise to propose: no fit with a part number used a run\n");
}

}  // namespace

void add_fleet_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<FleetOptions>();
  auto* cmd = app.add_subcommand(
      "fleet",
      "Control charts of k1, k0, B0 and the std ratio, and of the acceptance scale "
      "factor K and its temperature coefficient, across the fleet's stations");
  cmd->footer(exit_status_footer({{kExitOk, "the charts were written"}}));
  cmd->add_option("--pg", o->pg, "the fleet's PostgreSQL (libpq URL)")->required();
  cmd->add_option("--part", o->part, "only this part number");
  cmd->add_option("--since", o->since,
                  "only calibrations created, and acceptance runs started, at or after (ISO-8601)");
  cmd->add_option("--out", o->out, "write DIR/fleet.html");
  cmd->add_flag("--json", o->json, "print the charts as JSON");
  cmd->add_flag("--propose-noise", o->propose_noise,
                "propose each part's noise from its runs: the IEEE 952 terms (N, B, K) of each "
                "run's compensated 1 Hz record (its samples must have been forwarded), their "
                "median over at least 3 runs and a trust factor from their spread, as a "
                "[part.\"PN\".noise] block for the part file");
  cmd->callback([o, &status] {
    run_fleet(*o);
    status.exit_code = 0;
  });
}

}  // namespace station
