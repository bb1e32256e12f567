// `station replay LOG --db PATH --run ID`: a recorded session (the run's CAN log from
// `run --record-can`, and its database) goes through the same counter-board driver and the same
// binning and fit again; the result is compared with the stored fit (gpsd-style regression).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "drivers/counters/counter_boards.hpp"
#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/common/logging.hpp"
#include "station/config/config.hpp"
#include "station/daemon/sample.hpp"
#include "station/session/replay_can.hpp"
#include "station/session/session_replay.hpp"
#include "station/store/calibration.hpp"
#include "station/store/fit_json.hpp"

namespace station {
namespace {

namespace dr = station::drivers;
namespace sc = station::compensation;

struct ReplayCommandOptions {
  std::string log, db;
  std::int64_t run = 1;
  bool json = false;
  double rtol = 0, atol = 0;
};

// `station replay DIR`: a whole session through the daemon (station/session/session_replay.*).
int run_session_replay(const ReplayCommandOptions& o) {
  station::ReplayOptions ro{o.log, o.db, o.rtol, o.atol};
  ro.narrate = true;
  const ReplayReport r = replay_session(ro);
  if (o.json) {
    std::cout << r.json().dump(2) << '\n';
  } else if (r.same) {
    fmt::print("{}: same ({} ticks, {} bins, {} events, {} fits)\n", o.log, r.ticks, r.bins,
               r.events, r.fits);
  } else {
    fmt::print("{}: DIFFERS\n  first difference: {}\n", o.log, r.first_difference.dump());
    for (const auto& [quantity, d] : r.max_abs_difference.items())
      if (d.get<double>() > 0)
        fmt::print("  max |difference| {}: {:.3e}\n", quantity, d.get<double>());
    for (const auto& n : r.notes) fmt::print("  {}\n", n);
  }
  return r.same ? 0 : 1;
}

/// Per serial: the stored samples (tick times, record window, flags) of the run.
using StoredSamples = std::map<std::string, std::vector<SampleRow>>;

/// Re-derives every serial's samples from the log: rate and temperatures from the replayed
/// driver, tick time / window / flags from the stored run.
StoredSamples replay_samples(const ReplayCommandOptions& o, const std::vector<RunSlot>& slots,
                             const StoredSamples& stored) {
  auto records = dr::can::read_candump_log(o.log);
  const auto syncs = logged_syncs(records);
  const std::size_t ticks = stored.at(slots.front().serial).size();
  if (syncs.size() != ticks) {
    throw InputError(fmt::format("{}: {} SYNC frames, but run {} has {} ticks", o.log, syncs.size(),
                                 o.run, ticks));
  }
  dr::counters::CounterBoardsConfig cfg;
  // The log, not the wall clock, says when a latch's answers end: a stalled machine replays
  // the same frames as a fast one.
  cfg.wall_clock_deadline = false;
  for (const auto& s : slots)
    cfg.slots.push_back({static_cast<std::uint8_t>(s.node), s.serial, s.pulse_weight_arcsec});
  dr::counters::CounterBoards boards(std::make_unique<ReplayCanTransport>(std::move(records)), cfg);
  StoredSamples out;
  for (std::size_t k = 0; k < ticks; ++k) {
    auto tick = boards.tick(syncs[k]);
    if (!tick) throw InputError(fmt::format("{}: tick {}: {}", o.log, k, tick.error().message));
    for (const auto& rd : tick.value().readings) {
      // The gyro part through the daemon's own path; time, window and flags as recorded.
      const SampleRow& recorded = stored.at(rd.serial)[k];
      SampleRow r;
      apply_reading(&rd, r);
      r.serial = recorded.serial;
      r.t_s = recorded.t_s;
      r.recording = recorded.recording;
      r.air_c = recorded.air_c;
      r.setpoint_c = recorded.setpoint_c;
      r.flags = recorded.flags;
      out[rd.serial].push_back(std::move(r));
    }
  }
  return out;
}

int run_replay(const ReplayCommandOptions& o) {
  Store store(o.db, OpenMode::read_only);
  const auto run = store.find_run(o.run);
  if (!run) throw InputError(fmt::format("{}: no run {}", o.db, o.run));
  const auto slots = store.run_slots(o.run);
  if (slots.empty()) throw InputError(fmt::format("{}: run {} has no slots", o.db, o.run));
  const double bin_s =
      parse_station_config(run->config_text, fmt::format("{}:run {} config", o.db, o.run)).bin_s;
  StoredSamples stored;
  for (const auto& s : slots) stored[s.serial] = store.samples(o.run, s.serial, false);
  const StoredSamples replayed = replay_samples(o, slots, stored);
  nlohmann::json report{{"run_id", o.run}, {"log", o.log}, {"gyros", nlohmann::json::array()}};
  bool identical = true;
  for (const auto& slot : slots) {
    const auto fit = store.latest_fit(slot.serial);
    if (!fit || fit->runs != std::vector<std::int64_t>{o.run}) continue;
    const auto data =
        sc::model_data_from_bins(bin_samples(replayed.at(slot.serial), bin_s), slot.earth_rate_dph);
    const auto again = sc::fit_model(data.view(), fit->fit.spec);
    double worst = 0;  // largest |replayed - stored| in units of the stored standard error
    for (std::size_t i = 0; i < again.coefficients.size(); ++i) {
      worst = std::max(worst, std::abs(again.coefficients[i] - fit->fit.coefficients[i]) /
                                  fit->fit.std_errors[i]);
    }
    identical = identical && worst <= 1e-9;
    report["gyros"].push_back({{"serial", slot.serial},
                               {"stored", coefficients_json(fit->fit)},
                               {"replayed", coefficients_json(again)},
                               {"max_diff_in_std_errors", worst}});
  }
  report["identical"] = identical;
  store.db().check_unchanged();
  if (o.json) {
    std::cout << report.dump(2) << '\n';
  } else {
    for (const auto& g : report["gyros"]) {
      fmt::print("{}: replayed fit {} the stored one (max difference {:.2e} std errors)\n",
                 g["serial"].get<std::string>(),
                 g["max_diff_in_std_errors"].get<double>() <= 1e-9 ? "equals" : "DIFFERS FROM",
                 g["max_diff_in_std_errors"].get<double>());
    }
  }
  return identical ? 0 : 1;
}

}  // namespace

void add_replay_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<ReplayCommandOptions>();
  auto* cmd = app.add_subcommand(
      "replay",
      "Replay a recorded session directory through the daemon and compare with its result "
      "(exit 0 same, 1 differs, 2 bad session); or a run's CAN log against its database");
  cmd->footer(exit_status_footer(
      {{0, "the replay gives what was recorded (within the tolerances)"},
       {1, "it differs, or a recorded file was changed (named with its line)"}}));
  cmd->add_option("source", o->log,
                  "session directory (run --record DIR), or a candump log (run --record-can)")
      ->required();
  cmd->add_option("--db", o->db,
                  "session: keep the replayed database in this new file; CAN log: the run's "
                  "database");
  cmd->add_option("--run", o->run, "CAN log: run id")->capture_default_str();
  // A NaN or infinite tolerance would accept any value: a replay that cannot fail (exit 2).
  const CLI::Validator finite_tolerance(
      [](const std::string& text) {
        double v = NAN;
        const bool ok = CLI::detail::lexical_cast(text, v) && std::isfinite(v) && v >= 0;
        return ok ? std::string() : "a tolerance is a finite number >= 0, not " + text;
      },
      "FINITE>=0");
  cmd->add_option("--rtol", o->rtol, "session: relative tolerance per value (default exact)")
      ->check(finite_tolerance);
  cmd->add_option("--atol", o->atol, "session: absolute tolerance per value (default exact)")
      ->check(finite_tolerance);
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->callback([o, &status] {
    if (std::filesystem::is_directory(o->log)) {
      LogOptions lo;  // the replayed daemon's info lines are the recording's, not news
      lo.console_level = spdlog::level::warn;
      setup_logging(lo);
      status.exit_code = run_session_replay(*o);
      return;
    }
    if (o->db.empty()) throw InputError(o->log + ": a CAN log needs --db (the run's database)");
    try {
      status.exit_code = run_replay(*o);
    } catch (const std::runtime_error& e) {
      if (dynamic_cast<const InputError*>(&e) != nullptr) throw;
      throw InputError(e.what());  // a malformed log line: "path:line: what"
    }
  });
}

}  // namespace station
