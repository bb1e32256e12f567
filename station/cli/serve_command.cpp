// `station serve`: the long-running service. The rig stays connected and watched between runs
// (IdleWatch: lamps amber, faults as events), the live page, API and metrics are served, one
// protocol runs at a time when the API asks, a run a killed daemon left unfinished resumes at
// start exactly as `run` resumes it, and a run that fails is recorded and the service goes on.
// Under systemd: Type=notify (READY once the HTTP service is bound), WATCHDOG=1 every second
// whether idle or running; SIGTERM ends the running run as 'stopped' and then the service.
// SIGUSR1 is the hand-over for a package upgrade: the running run is left resumable (everything
// committed, outputs as they are) and the service exits 75 (EX_TEMPFAIL), which systemd's
// Restart=on-failure answers by starting the new binary, which resumes the run.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "drivers/common/clock.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/cli/progress_display.hpp"
#include "station/common/input_error.hpp"
#include "station/common/logging.hpp"
#include "station/daemon/daemon_setup.hpp"
#include "station/daemon/host.hpp"
#include "station/daemon/rig.hpp"
#include "station/fleet/forwarder_thread.hpp"
#include "station/http/live_service.hpp"
#include "station/http/serve_control.hpp"
#include "station/parts/judged_fit.hpp"

namespace station {
namespace {

std::atomic<bool> g_stop{false};       // SIGTERM/SIGINT: the service ends
std::atomic<bool> g_run_stop{false};   // the running run ends (API stop, or the signal)
std::atomic<bool> g_run_abort{false};  // ... without bins or fit (API abort)
std::atomic<bool> g_detach{false};     // SIGUSR1: leave the run resumable, exit for a restart

/// The exit status after SIGUSR1 (sysexits.h EX_TEMPFAIL): "restart me", not a failure of a run.

std::atomic<bool> g_terminated{false};  // SIGTERM/SIGINT seen: a stop beats a hand-over

// A stop and a hand-over request both pending: the stop wins whichever handler runs first (the
// kernel stacks the frames of signals pending together, so the later one's handler runs first).
void on_stop_signal(int) {
  g_terminated.store(true);
  g_detach.store(false);
  g_stop.store(true);
  g_run_stop.store(true);
}

void on_detach_signal(int) {
  if (!g_terminated.load()) g_detach.store(true);
  g_stop.store(true);
}

struct ServeOptions {
  std::string config, db, http, token_file, parts, log_file;
};

/// A run that failed when the store could not write (disk full): closed as soon as it can be.
struct UnclosedRun {
  std::int64_t id = 0;
  std::string reason;
};

/// Everything a serve process holds.
struct Service {
  const StationConfig& config;
  Host& host;
  Store& store;
  LiveService& live;
  ServeControl& control;
  std::string parts_path;  ///< --parts (empty: the configuration's [station] parts)
  bool watchdog = false;
  std::optional<UnclosedRun> unclosed;  ///< a failed run still 'running' in the store
};

/// Records why run `id` failed and closes it as 'aborted' (with a `run_failed` event); false when
/// the store still cannot write (the run stays 'running' in the file meanwhile).
bool close_failed_run(Service& s, const UnclosedRun& u) {
  try {
    const auto run = s.store.find_run(u.id);
    if (!run || run->state != RunState::running) return true;  // closed already
    s.store.add_event(u.id, run->last_tick_s.value_or(0), Severity::error, "serve",
                      EventKind::run_failed, u.reason);
    s.store.finish_run(u.id, RunState::aborted);
    log("serve")->info("run {} closed as aborted (run_failed: {})", u.id, u.reason);
    return true;
  } catch (const std::exception& e) {
    log("serve")->error("run {} cannot be closed yet: {}", u.id, e.what());
    return false;
  }
}

/// A run's failure (the store or a bug; the sequencer does not throw for device faults): the
/// run is closed with the reason, at once or as soon as the store writes again, so the next
/// start does not resume into the same wall; an API start that never got its run is answered.
/// `refused`: the request was refused before its run was created (an InputError: the protocol
/// is beyond what the rig can do), answered 400; otherwise the station could not record, 503.
void run_failed(Service& s, std::optional<std::int64_t> id, const std::string& why,
                bool refused = false) {
  log("serve")->error("run {} failed: {}", id.value_or(0), why);
  s.live.hub().run_ended(id.value_or(0), fmt::format("failed: {}", why));
  if (!id) {
    s.control.start_failed(why, refused ? 400 : 503);
    return;
  }
  UnclosedRun u{*id, why};
  if (!close_failed_run(s, u)) s.unclosed = std::move(u);
}

/// The sequencer's hooks of a run under serve: the API's stop, abort and hand-over, the
/// watchdog, the live page, systemd's status line; `run_id` is set once the run exists.
SequencerOptions serve_hooks(Service& s, const std::string& operator_name,
                             std::optional<std::int64_t>& run_id, ProgressDisplay& progress) {
  SequencerOptions so;
  so.operator_name = operator_name;
  so.stop = &g_run_stop;
  so.abort = &g_run_abort;
  so.detach = &g_detach;
  if (s.watchdog) so.watchdog = [] { sd_notify(0, "WATCHDOG=1"); };
  so.on_run_start = [&s, &run_id](std::int64_t id, const Protocol&, const std::vector<RunSlot>&) {
    run_id = id;
    s.control.started(id);
  };
  live::attach(s.live.hub(), so);
  attach_progress(so, progress);
  so.http_url = s.live.url();
  return so;
}

/// Runs a started run (a new one, or the one a killed daemon left) to its end; a failure is
/// recorded, never fatal to the service.
void run_one(Service& s, const StartPlan& plan, const std::string& operator_name) {
  // The run this call made or resumed (not the hub's last one: a run that cannot even be
  // created must not close an earlier run).
  std::optional<std::int64_t> run_id;
  // systemd's status line (`systemctl status`): the run's progress each tick.
  ProgressDisplay progress(nullptr, false, 0.0, s.config.bin_s, notify_status);
  s.control.set_busy(true);
  // A stop or abort meant for an earlier run must not end this one.
  if (!g_stop.load()) g_run_stop.store(false);
  g_run_abort.store(false);
  if (plan.resume) run_id = plan.resume->id;
  try {
    SequencerOptions so = serve_hooks(s, operator_name, run_id, progress);
    so.part_limits = slot_part_limits(plan.config, s.parts_path);  // the run's gyros' parts
    const RunOutcome out = s.host.run(plan, std::move(so));
    s.live.hub().run_ended(out.run_id, std::string(to_string(out.state)));
    notify_status(fmt::format("idle; run {} {}", out.run_id, to_string(out.state)));
    log("serve")->info("run {} {} at t = {:.0f} s after {} ticks", out.run_id, to_string(out.state),
                       out.t_s, out.ticks);
  } catch (const InputError& e) {
    run_failed(s, run_id, e.what(), !run_id.has_value());
  } catch (const std::exception& e) {
    run_failed(s, run_id, e.what());
  }
  if (!g_stop.load()) g_run_stop.store(false);
  g_run_abort.store(false);
  s.control.set_busy(false);
}

/// What keeps the service from starting a run: the rig's idle faults and the store's.
std::string service_fault(Service& s, const IdleReading& r) {
  std::vector<std::string> faults;
  if (!r.fault.empty()) faults.push_back(r.fault);
  if (s.unclosed && close_failed_run(s, *s.unclosed)) s.unclosed.reset();
  if (s.unclosed) {
    faults.push_back(
        fmt::format("storage: run {} cannot be closed: {}", s.unclosed->id, s.unclosed->reason));
  } else if (!r.storage_error.empty()) {
    faults.push_back(fmt::format("storage: {}", r.storage_error));
  }
  return fmt::format("{}", fmt::join(faults, "; "));
}

void idle_until_stopped(Service& s) {
  while (!g_stop.load()) {
    IdleReading r = s.host.look();
    r.fault = service_fault(s, r);
    s.live.hub().idle(r);
    s.control.set_fault(r.fault, s.unclosed.has_value() || !r.storage_error.empty());
    if (s.watchdog) sd_notify(0, "WATCHDOG=1");
    // The control refuses a start while the last look found a fault (the start check of a new
    // run); the one start rule (run_start.hpp) decides the rest.
    const auto req = s.control.next(std::chrono::milliseconds(1000));
    if (!req) continue;
    // An API start never touches another run: one left unfinished (a failed close) is refused.
    std::optional<StartPlan> plan;
    try {
      StartRequest ask{req->protocol, false, std::nullopt, {}};
      ask.gyros = req->gyros;
      plan = s.host.start(ask);
      if (plan->resume)
        throw InputError(
            fmt::format("run {} is unfinished: it must be closed first", plan->resume->id));
    } catch (const std::exception& e) {
      run_failed(s, std::nullopt, e.what());
      s.control.set_busy(false);
      continue;
    }
    run_one(s, *plan, req->operator_name);
  }
}

LiveServiceOptions live_options(const ServeOptions& o, const StationConfig& config) {
  LiveServiceOptions lo;
  lo.listen = o.http.empty() ? config.http.listen : o.http;
  lo.token_file = o.token_file.empty() ? config.http.token_file : o.token_file;
  lo.db_path = o.db;
  lo.info.station = config.name;
  lo.info.bin_s = config.bin_s;
  for (std::size_t i = 0; i < config.slots.size(); ++i)  // the live page's start form
    lo.info.rig_slots.push_back({{"slot", i + 1},
                                 {"node", config.slots[i].node},
                                 {"serial", config.slots[i].serial},
                                 {"part", config.slots[i].part}});
  return lo;
}

/// Store and forward ([fleet]): its own thread and connections; stopped before the hub goes.
std::unique_ptr<fleet::ForwarderThread> start_forwarder(const ServeOptions& o,
                                                        const StationConfig& config,
                                                        LiveService& live) {
  if (!config.fleet) return nullptr;
  return std::make_unique<fleet::ForwarderThread>(
      o.db, fleet::fleet_target(*config.fleet),
      fleet::ForwardOptions{config.fleet->samples, 50'000, config.name}, config.fleet->interval_s,
      [&live](const fleet::ForwarderStatus& f) {
        live.hub().fleet(f.to_json());
        live.hub().metrics().fleet({f.state, f.waiting_s, f.backlog.runs, f.backlog.rows,
                                    f.last_success_unix_s, f.errors_total});
      });
}

/// SIGUSR1's hand-over. Everything is committed (each tick is its own transaction). Leave now,
/// as a kill would: no destructors, so the GPIO lines keep their levels (the gyros stay powered
/// and the lamps as they are) until the new process takes the rig over a few seconds later.
[[noreturn]] void exit_for_restart() {
  log("serve")->info("SIGUSR1: exiting {} for a restart (a running run resumes)", kExitRestart);
  std::fflush(stdout);
  std::fflush(stderr);
  spdlog::shutdown();
  std::_Exit(kExitRestart);
}

// The real rig on the wall clock, runs started over the API; the run is the one host's.
int serve(const ServeOptions& o) {
  const StationConfig config = load_station_config(o.config);
  slot_part_limits(config, o.parts);  // a bad part file stops here
  const auto locks = lock_db_and_devices(o.db, &config);
  Rig rig = build_rig(config, {});
  if (rig.gpio) {
    if (auto r = rig.gpio->open(); !r) log("serve")->warn("gpio: {}", r.error().message);
  }
  Store store(o.db);
  drivers::MonotonicClock clock;
  // The API's gyros are checked on its thread, before the request reaches the loop.
  const std::string parts_path = o.parts.empty() ? config.parts_path : o.parts;
  ServeControl control(config.http.protocol_dir, g_run_stop, g_run_abort,
                       [&config, parts_path](const std::vector<SlotGyro>& gyros) {
                         return gyro_problems(config, gyros, parts_path, true);
                       });
  LiveService live(live_options(o, config), control);
  Host host(config, rig, store, clock, [&live](const RunEvent& e) { live.hub().event(e); });
  std::uint64_t watchdog_usec = 0;
  Service s{
      config,      host, store, live, control, o.parts, sd_watchdog_enabled(0, &watchdog_usec) > 0,
      std::nullopt};
  auto forwarder = start_forwarder(o, config, live);
  sd_notify(0, "READY=1");
  // A run a killed daemon left unfinished goes on first, by the one start rule; one that no
  // longer fits the configuration is refused (exit 2, the run untouched: README, upgrades).
  StartRequest resume_only;
  resume_only.resume_only = true;
  if (const StartPlan plan = host.start(resume_only); plan.resume)
    run_one(s, plan, plan.resume->operator_name);
  idle_until_stopped(s);
  sd_notify(0, "STOPPING=1");
  forwarder.reset();
  live.shutdown();
  if (g_detach.load()) exit_for_restart();
  live.exit_if_abandoned(0);
  return 0;
}

}  // namespace

void add_serve_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<ServeOptions>();
  auto* cmd = app.add_subcommand(
      "serve",
      "Run the station as a service: rig watched between runs, live page, JSON API, "
      "metrics; runs started and stopped over HTTP (schemas/api.md)");
  cmd->footer(exit_status_footer(
      {{0, "stopped by SIGTERM or SIGINT (a running run ends as stopped)"},
       {kExitRestart,
        "SIGUSR1: everything committed, a running run left resumable; the unit restarts it"}}));
  cmd->add_option("--config", o->config, "station configuration (TOML)")->required();
  cmd->add_option("--db", o->db, "SQLite database")->required();
  cmd->add_option("--http", o->http,
                  "listen at HOST:PORT (default: [http] listen, else 127.0.0.1:8080; "
                  "127.0.0.1:0 picks a free port and prints it)");
  cmd->add_option("--token-file", o->token_file,
                  "the API's bearer token (created 0600 at first start; default: [http] "
                  "token_file, else DB.token)");
  cmd->add_option("--parts", o->parts, "part file (overrides [station] parts)");
  cmd->add_option("--log-file", o->log_file, "rotating log file");
  cmd->callback([o, &status] {
    setup_daemon_logging(spdlog::level::info, o->log_file);
    on_stop_signals(on_stop_signal);
    on_signal(SIGUSR1, on_detach_signal);
    status.exit_code = serve(*o);
  });
}

}  // namespace station
