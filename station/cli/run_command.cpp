// `station run`: the daemon. --sim runs the embedded simulated rig; otherwise a real rig from
// --config. SIGTERM/SIGINT end the run cleanly; under systemd it notifies READY and the watchdog.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <atomic>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "drivers/can/candump_log.hpp"
#include "drivers/common/clock.hpp"
#include "drivers/registry/dialects.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/cli/number_options.hpp"
#include "station/cli/progress_display.hpp"
#include "station/cli/run_summary.hpp"
#include "station/cli/text_options.hpp"
#include "station/common/logging.hpp"
#include "station/common/process_lock.hpp"
#include "station/common/text_rule.hpp"
#include "station/daemon/daemon_setup.hpp"
#include "station/daemon/host.hpp"
#include "station/daemon/rig.hpp"
#include "station/daemon/rig_probe.hpp"
#include "station/http/live_service.hpp"
#include "station/parts/judged_fit.hpp"
#include "station/session/session_recording.hpp"
#include "station/sim/sim_run.hpp"

namespace station {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<bool> g_abort{false};  // the API's abort: end without bins or fit

void on_stop_signal(int) {
  g_stop.store(true);
}

struct RunOptions {
  bool sim = false, json = false, fresh = false, verify = false;
  std::string config, protocol = "paper", db, operator_name, log_file, record_can, record;
  std::string parts, part;          ///< --parts FILE, --part PN (--sim)
  std::vector<std::string> faults;  ///< --sim: "T:COMMAND"
  std::vector<std::string> slots;   ///< --slot N=SERIAL[,PART]: the run's gyros
  int gyros = 4;
  std::uint64_t seed = 1;
  std::string gyro_preset = "station";
  std::string chamber_model = "generic_plc";
  std::string turntable_model = "generic_plc";
  std::string acutrol_framing = "bare";  ///< --sim: a simulated ACUTROL's reply framing
  double latitude_deg = 39.9;
  std::vector<std::string> axes;  ///< --sim --axis: slot i's input axis
  double speed = 0;               ///< --sim: simulated s per wall s (0: as fast as possible)
  std::string http;               ///< --http HOST:PORT (empty: no HTTP service)
  std::string token_file;
};

/// The live service of this run (HTTP only with --http).
LiveServiceOptions live_options(const RunOptions& o, const std::string& db,
                                const std::string& station, bool sim) {
  LiveServiceOptions lo;
  lo.listen = o.http;
  lo.token_file = o.token_file;
  lo.db_path = db;
  lo.info.station = station;
  lo.info.sim = sim;
  if (sim && o.speed > 0) lo.info.speed = o.speed;
  return lo;
}

/// Hooks the live hub into a run's options.
void attach_live(LiveService& live, SequencerOptions& so) {
  so.abort = &g_abort;
  live::attach(live.hub(), so);
  so.http_url = live.url();
}

/// Forwards to a tap attached later (the CAN log starts after the probe: its SYNC is no tick).
struct DeferredTap final : drivers::Tap {
  drivers::Tap* target = nullptr;
  void on_exchange(const drivers::TapRecord& r) noexcept override {
    if (target != nullptr) target->on_exchange(r);
  }
};

/// `run --config`: the CAN log or session recording, attached after the start check (the
/// probe's exchanges are no part of the run).
struct Recording {
  std::ofstream can_log;
  std::optional<drivers::can::CandumpTap> can_tap;
  std::optional<SessionRecording> session;
  void start(const RunOptions& o, DeferredTap& tap, const StationConfig& config,
             const Protocol& protocol) {
    if (!o.record.empty()) {
      session.emplace(o.record);
      tap.target = &session->tap();
      session->start(config, protocol, false, std::nullopt);
    } else if (!o.record_can.empty()) {
      can_log.open(o.record_can, std::ios::app);
      if (!can_log) throw InputError(fmt::format("{}: cannot write the CAN log", o.record_can));
      tap.target = &can_tap.emplace(can_log, "can0");
    }
  }
  void hook(SequencerOptions& so) {
    if (!session) return;
    so.on_tick = [this](const TickReport&) { session->after_tick(); };
    so.on_resume = [this](double last_s, double next_s) { session->resumed(last_s, next_s); };
  }
};

/// The hooks of a run on the rig: the operator, Ctrl-C, part limits, the watchdog, the
/// recording and the live page.
SequencerOptions real_hooks(const RunOptions& o, std::map<std::string, PartLimits> part_limits,
                            Recording& rec, LiveService& live) {
  SequencerOptions so;
  so.operator_name = o.operator_name;
  so.stop = &g_stop;
  so.part_limits = std::move(part_limits);
  std::uint64_t watchdog_usec = 0;
  if (sd_watchdog_enabled(0, &watchdog_usec) > 0) so.watchdog = [] { sd_notify(0, "WATCHDOG=1"); };
  rec.hook(so);
  attach_live(live, so);
  return so;
}

// The real rig on the wall clock: the start check, the one start rule, the one host's run.
int run_real(const RunOptions& o) {
  const StationConfig config = load_station_config(o.config);
  if (!o.part.empty()) throw InputError("--part is for --sim; give a rig's parts with --slot");
  slot_part_limits(config, o.parts);  // a bad part file stops here
  StartRequest request{load_protocol(o.protocol), o.fresh, std::nullopt, {}};
  for (const auto& text : o.slots) request.gyros.push_back(parse_slot_gyro(text, "--slot"));
  const auto locks = lock_db_and_devices(o.db, &config);
  // The gyros are checked before the rig is touched; the rig is built naming them.
  const StationConfig named = refuse_bad_gyros(o.db, config, request, o.parts);
  DeferredTap tap;
  Recording rec;  // before the rig: closing the rig's GPIO still writes through the tap
  RigOptions ro;
  ro.tap = &tap;
  Rig rig = build_rig(named, ro);
  // The start check: every device read once before anything moves or the database is touched.
  request.rig_problems = unreachable_devices(named, rig);
  refuse_broken_rig(o.db, request);
  Store store(o.db);
  drivers::MonotonicClock clock;
  Host host(config, rig, store, clock);
  const StartPlan plan = host.start(request);  // the run's gyros: plan.config
  rec.start(o, tap, plan.config, plan.protocol);
  OneRunControl control(g_stop, g_abort);
  LiveService live(live_options(o, o.db, config.name, false), control);
  const auto part_limits = slot_part_limits(plan.config, o.parts);
  SequencerOptions so = real_hooks(o, part_limits, rec, live);
  // Progress: a redrawn line on a terminal, a line every 5 minutes of run time in a log, and
  // systemd's status line under a service.
  ProgressDisplay progress(stderr, ::isatty(STDERR_FILENO) != 0, 300.0, config.bin_s,
                           notify_status);
  attach_progress(so, progress);
  sd_notify(0, "READY=1");
  const RunOutcome out = host.run(plan, std::move(so));
  progress.finish();
  live.hub().run_ended(out.run_id, std::string(to_string(out.state)));
  live.shutdown();
  if (rec.session) rec.session->finish(store, out.run_id);
  sd_notify(0, "STOPPING=1");
  std::cout << run_summary_text(
      rig_run_summary(store, out.run_id, to_string(out.state), out.t_s, out.ticks, o.db,
                      part_limits));
  live.exit_if_abandoned(0);
  return 0;
}

/// --fault TICK:COMMAND, each checked for its form: TICK whole seconds of the run in plain
/// digits (no sign, exponent, fraction, hex or space: "1e99", "inf" and "0x10" are refused, not
/// read as a time no run reaches); the run's end is checked against the protocol in sim_run.
std::vector<std::pair<double, std::string>> parse_faults(const std::vector<std::string>& faults) {
  std::vector<std::pair<double, std::string>> out;
  for (const auto& f : faults) {
    const auto colon = f.find(':');
    const std::string tick = f.substr(0, colon);
    std::int64_t at_s = -1;
    const auto parsed = std::from_chars(tick.data(), tick.data() + tick.size(), at_s);
    const bool digits = !tick.empty() && tick.size() <= 12 &&
                        tick.find_first_not_of("0123456789") == std::string::npos;
    if (colon == std::string::npos || !digits || parsed.ec != std::errc() || colon + 1 >= f.size())
      throw InputError(fmt::format(
          "--fault '{}': expected TICK:COMMAND, TICK the run's second in digits (at most 12), "
          "e.g. 3000:door open",
          f));
    out.emplace_back(static_cast<double>(at_s), f.substr(colon + 1));
  }
  return out;
}

SimRunOptions sim_options(const RunOptions& o, const std::string& db) {
  SimRunOptions so;
  so.parts_path = o.parts;
  so.part_number = o.part;
  so.gyros = o.gyros;
  so.seed = o.seed;
  so.gyro_preset = o.gyro_preset;
  so.chamber_model = o.chamber_model;
  so.turntable_model = o.turntable_model;
  so.acutrol_framing = o.acutrol_framing;
  so.latitude_deg = o.latitude_deg;
  so.axes = o.axes;
  so.protocol = o.protocol;
  so.db_path = db;
  so.fresh = o.fresh;
  so.stop = &g_stop;
  so.record_can_path = o.record_can;
  so.record_dir = o.record;
  so.faults = parse_faults(o.faults);
  so.speed = o.speed;
  return so;
}

// The deterministic simulation (sim/sim_run.hpp) with the live page and the report.
int run_sim(const RunOptions& o) {
  const std::string db = o.db.empty() ? "station-sim.db" : o.db;
  SimRunOptions so = sim_options(o, db);
  sim_part_number(so);  // a bad part file stops here, before the database is locked
  const auto locks = lock_db_and_devices(db, nullptr);
  OneRunControl control(g_stop, g_abort);
  LiveService live(live_options(o, db, "simulated-rig", true), control);
  so.extend = [&live](SequencerOptions& s) { attach_live(live, s); };
  nlohmann::json report;
  try {
    report = o.verify ? run_simulated_with_verification(so) : run_simulated(so);
  } catch (const std::exception& e) {
    live.hub().run_ended(live.hub().current_run().value_or(0), fmt::format("failed: {}", e.what()));
    live.shutdown();
    throw;
  }
  live.hub().run_ended(report["run_id"].get<std::int64_t>(), report["state"].get<std::string>());
  live.shutdown();
  if (o.json) {
    std::cout << report.dump(2) << '\n';
  } else {
    report["report"] = report_command(db, report["run_id"].get<std::int64_t>());
    std::cout << run_summary_text(report);
  }
  std::cout.flush();
  live.exit_if_abandoned(0);
  return 0;
}

/// The simulated world's options of `run --sim`: gyros, seed, dialects, preset, latitude.
void add_sim_world_options(CLI::App* cmd, RunOptions& o) {
  cmd->add_option("--gyros", o.gyros, "simulated gyros")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  cmd->add_option("--seed", o.seed, "simulation seed")
      ->check(unsigned_integer())
      ->capture_default_str();
  cmd->add_option(
         "--chamber", o.chamber_model,
         "--sim: the dialect the simulated chamber speaks (" + drivers::chamber_models() + ")")
      ->capture_default_str();
  cmd->add_option(
         "--turntable", o.turntable_model,
         "--sim: the dialect the simulated table speaks (" + drivers::turntable_models() + ")")
      ->capture_default_str();
  cmd->add_option("--acutrol-framing", o.acutrol_framing,
                  "--sim, acutrol3000: replies as bare CR LF lines, or with the error/length "
                  "header (docs/DEVICES.md)")
      ->check(CLI::IsMember({"bare", "header"}))
      ->capture_default_str();
  cmd->add_option("--gyro-preset", o.gyro_preset,
                  "simulated gyros: station (strong thermal effect) or paper (the paper's "
                  "proportions: std ratio ~0.13)")
      ->check(CLI::IsMember({"station", "paper"}))
      ->capture_default_str();
  cmd->add_option("--latitude", o.latitude_deg, "simulated site latitude, deg")
      ->capture_default_str();
  cmd->add_option("--axis", o.axes,
                  "--sim: the input axis of slot 1, 2, ... in turn (up, north, south, east, west "
                  "or heading:DEG; the rest up): a horizontal one is mounted so on the "
                  "simulated table (positions, issue 36)");
}

/// What a run records and the simulation's fault script and parts.
void add_record_and_fault_options(CLI::App* cmd, RunOptions& o) {
  auto* record =
      cmd->add_option("--record", o.record,
                      "record the session in this directory: session.toml, can.log, modbus.log, "
                      "gpio.log, result.json (schemas/session.md)");
  cmd->add_option("--record-can", o.record_can,
                  "write only the CAN frames, in can-utils' candump format, to this file")
      ->excludes(record);
  cmd->add_option(
      "--fault", o.faults,
      "--sim: at tick T (whole seconds, within the protocol's span: each step's timeout, or "
      "its nominal duration and 7 days for a wait without one; one the run ends before is "
      "warned about) inject a simrig fault command, T:COMMAND "
      "(docs/SIMRIG.md), e.g. '3000:door open', or T:kill (the daemon SIGKILLs "
      "itself before tick T, to record a killed and resumed run) or T:sigint (it raises SIGINT "
      "after tick T: the operator's stop); repeatable");
  cmd->add_option("--parts", o.parts,
                  "part file (TOML, schemas/parts.schema.json): each fit gets a verdict against "
                  "its slot's part (overrides [station] parts; with --sim: applied to every "
                  "simulated gyro)");
  cmd->add_option("--part", o.part,
                  "--sim: the simulated gyros' part number (default: the part file's first, in "
                  "sort order)");
  cmd->add_option("--slot", o.slots,
                  "--config: the gyro on slot N (from 1, the order of the configuration's "
                  "[[slot]] tables) for this run, N=SERIAL or N=SERIAL,PART; repeatable. A slot "
                  "not given takes the configuration's serial (and part); a resume keeps the "
                  "run's own and refuses others");
}

}  // namespace

void add_run_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<RunOptions>();
  auto* cmd = app.add_subcommand("run", "Run a test protocol on a rig (or on the simulated rig)");
  cmd->footer(exit_status_footer(
      {{0, "the run ended: completed, incomplete, stopped (SIGTERM, SIGINT, the API) or aborted"},
       {2,
        "bad input or setup (options, configuration, protocol, a database or device in use), "
        "or the store could not write mid-run (disk full): the run stays resumable"}}));
  auto* sim = cmd->add_flag("--sim", o->sim, "simulated rig on the simulated clock");
  cmd->add_option("--config", o->config, "station configuration (TOML)")->excludes(sim);
  cmd->add_option("--protocol", o->protocol, "protocol file or shipped name")
      ->capture_default_str();
  cmd->add_option("--db", o->db, "SQLite database (default with --sim: station-sim.db)");
  cmd->add_option("--operator", o->operator_name, "operator recorded with the run")
      ->check(note_text(kMaxPersonBytes));
  cmd->add_flag("--new", o->fresh, "start a new run even if one was left unfinished");
  add_sim_world_options(cmd, *o);
  cmd->add_option("--log-file", o->log_file, "rotating log file");
  add_record_and_fault_options(cmd, *o);
  cmd->add_flag("--json", o->json, "print one JSON object at the end (--sim)");
  cmd->add_flag("--verify", o->verify,
                "--sim: release each passing fit, then run the same gyros again (independent "
                "noise) and verify the released calibrations on that run")
      ->needs(sim);
  cmd->add_option("--speed", o->speed,
                  "--sim: simulated seconds per wall second, to watch a run live (600: the 13 h "
                  "cycle in ~80 s; default: as fast as possible)")
      ->check(finite_within(1.0, 1e6, "x"));  // below 1 a stop would wait a whole slowed tick
  cmd->add_option("--http", o->http,
                  "serve the live page, JSON API and /metrics at HOST:PORT (schemas/api.md); "
                  "127.0.0.1:0 picks a free port and prints it");
  cmd->add_option("--token-file", o->token_file,
                  "the API's bearer token (created 0600 at first start; default DB.token)");
  cmd->callback([o, &status] {
    setup_daemon_logging(o->sim ? spdlog::level::warn : spdlog::level::info, o->log_file);
    on_stop_signals(on_stop_signal);
    if (!o->sim && o->speed > 0) throw InputError("--speed is for --sim (a rig runs at 1 Hz)");
    if (!o->sim && !o->axes.empty())
      throw InputError("--axis is for --sim (a rig's input axes are its [[slot]] axis keys)");
    if (o->sim && !o->slots.empty())
      throw InputError("--slot is for --config (the simulated gyros are SIM-0001, ...)");
    if (!o->sim && (o->config.empty() || o->db.empty())) {
      throw InputError("run: give --config FILE and --db PATH, or --sim");
    }
    status.exit_code = o->sim ? run_sim(*o) : run_real(*o);
  });
}

}  // namespace station
