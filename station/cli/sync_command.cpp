// `station sync [--db DB] (--pg URL | --config FILE) [--init] [--samples]`: forwards what the
// station's database holds to the fleet's PostgreSQL once, until nothing is pending (the
// forwarder `serve` runs on its own thread, station/fleet/forwarder.hpp). --init creates or
// migrates the central schema first. Every server call has a deadline (fleet/pg.hpp): a server
// that stops answering ends the command with the call that timed out. Exit 0: everything
// acknowledged; 1: the server refused items (each outbox row says why), could not be reached or
// did not answer in time; 2: bad input.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/cli/text_options.hpp"
#include "station/common/input_error.hpp"
#include "station/config/config.hpp"
#include "station/fleet/fleet_schema.hpp"
#include "station/fleet/forwarder.hpp"
#include "station/store/store.hpp"

namespace station {
namespace {

struct SyncOptions {
  std::string db, pg, config, station;
  bool init = false, samples = false, json = false, retry_held = false;
  std::int64_t batch_rows = 50'000;
  std::optional<double> timeout_s;  ///< --timeout-s, else [fleet] timeout_s, else 60 s
};

/// The newest run's station name: what a fit with no runs left in the file is filed under.
std::string recorded_station(Store& store) {
  auto st = store.cached("SELECT station FROM runs ORDER BY id DESC LIMIT 1");
  return st->step() ? st->column_text(0) : std::string("station");
}

struct Resolved {
  fleet::PgTarget target;
  fleet::ForwardOptions forward;
};

Resolved resolve(const SyncOptions& o, Store* store) {
  Resolved r;
  if (!o.config.empty()) {
    const auto cfg = load_station_config(o.config);
    if (!cfg.fleet) throw InputError(fmt::format("{}: no [fleet] table (pg = URL)", o.config));
    r.target = fleet::fleet_target(*cfg.fleet);
    r.forward.samples = cfg.fleet->samples;
    r.forward.station = cfg.name;
  }
  if (!o.pg.empty()) {
    if (auto why = pg_url_problem(o.pg)) throw InputError(fmt::format("--pg: {}", *why));
    r.target.url = o.pg;
  }
  if (r.target.url.empty()) throw InputError("--pg URL or --config FILE with [fleet] is required");
  r.forward.samples = r.forward.samples || o.samples;
  r.forward.batch_rows = o.batch_rows;
  if (o.timeout_s) r.target.statement_timeout_s = *o.timeout_s;
  if (!o.station.empty()) r.forward.station = o.station;
  if (r.forward.station.empty() && store) r.forward.station = recorded_station(*store);
  return r;
}

int run_sync(const SyncOptions& o) {
  if (o.db.empty() && !o.init) throw InputError("--db DB is required (or --init alone)");
  // The station file first (migrates it: the outbox is migration 7), unless only --init.
  std::optional<Store> store;
  if (!o.db.empty()) store.emplace(o.db, OpenMode::existing);
  const Resolved r = resolve(o, store ? &*store : nullptr);
  if (o.init) {
    fleet::PgConnection pg(r.target);
    std::vector<std::string> recreated;
    const int before = fleet::init_fleet_schema(pg, &recreated);
    fmt::print(stderr, "fleet schema on {}: version {} -> {}{}{}\n", pg.where(), before,
               fleet::fleet_schema_version(),
               recreated.empty() ? "" : "; re-created missing: ", fmt::join(recreated, ", "));
    if (o.db.empty()) return 0;
  }
  fleet::Forwarder fwd(o.db, r.target, r.forward);
  if (o.retry_held) fwd.release_held();
  fleet::PassResult total;
  for (;;) {
    const auto p = fwd.pass();
    total += p;
    if (!p.more || (p.items == 0 && p.rows == 0)) break;
  }
  const auto left = fwd.backlog();
  if (o.json) {
    std::cout << nlohmann::json{{"items_sent", total.items},       {"rows_written", total.rows},
                                {"rows_appended", total.appended}, {"items_refused", total.failed},
                                {"last_error", total.last_error},  {"pending_runs", left.runs},
                                {"pending_items", left.items},     {"pending_rows", left.rows}}
                     .dump(2)
              << '\n';
  } else {
    fmt::print("sent {} items ({} rows written); pending: {} runs, {} items, {} rows\n",
               total.items, total.rows, left.runs, left.items, left.rows);
    if (total.failed > 0)
      fmt::print(stderr, "{} items refused or held, last: {}\n", total.failed, total.last_error);
    if (left.held > 0)
      fmt::print(stderr,
                 "{} items held: the server has a newer state of them than this file (a restored "
                 "backup?); nothing of them was written\n",
                 left.held);
  }
  return total.failed > 0 || left.held > 0 ? 1 : 0;
}

}  // namespace

void add_sync_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<SyncOptions>();
  auto* cmd = app.add_subcommand(
      "sync", "Forward the database's runs, fits and releases to the fleet's PostgreSQL once");
  cmd->footer(exit_status_footer(
      {{kExitOk, "everything pending was acknowledged by the server"},
       {kExitFailure,
        "the server could not be reached, did not answer a call in time (--timeout-s), refused "
        "items, or holds a newer state of some (a restored file: held)"}}));
  cmd->add_option("--db", o->db, "SQLite database of the station (optional with --init)");
  cmd->add_option("--pg", o->pg, "libpq connection URL (no password: PGPASSWORD or a passfile)");
  cmd->add_option("--config", o->config, "station configuration with a [fleet] table");
  cmd->add_option("--station", o->station, "station name for fits whose runs are gone")
      ->check(identifier_text());
  cmd->add_flag("--init", o->init, "create or migrate the central schema first");
  cmd->add_flag("--samples", o->samples, "forward the 1 Hz samples too");
  cmd->add_flag("--retry-held", o->retry_held,
                "check items held (the server had a newer state) again");
  cmd->add_option("--batch-rows", o->batch_rows, "appended rows per transaction")
      ->check(CLI::Range(1, 10'000'000));
  cmd->add_option("--timeout-s", o->timeout_s,
                  "longest one server call may take ([fleet] timeout_s, default 60): the client "
                  "gives up a little later, cancels it and exits 1 naming the call")
      ->check(CLI::Range(0.5, 3600.0));
  cmd->add_flag("--json", o->json, "print the totals as JSON");
  cmd->callback([o, &status] { status.exit_code = run_sync(*o); });
}

}  // namespace station
