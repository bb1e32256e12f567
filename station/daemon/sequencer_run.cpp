// The sequencer's outer loop: new or resumed run, absolute 1 Hz deadlines, clean end.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "compensation/earth_rate.hpp"
#include "drivers/common/tap.hpp"
#include "station/acceptance/acceptance_record.hpp"
#include "station/common/logging.hpp"
#include "station/daemon/resume.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/daemon/stopwatch.hpp"
#include "station/parts/judged_fit.hpp"
#include "station/store/calibration.hpp"
#include "station/store/fit_json.hpp"
#include "station/store/fit_verdicts.hpp"

#ifndef STATION_VERSION
#define STATION_VERSION "dev"
#endif

namespace station {

RunState Sequencer::finish(RunState end_state, double t_s) {
  rest_table(t_s);                        // a ladder stopped or timed out mid-step
  drive_outputs(t_s, SafetyOutputs{});    // the run is over: gyro power off, lamps dark
  const auto lossy = close_outages(t_s);  // serial -> why its record window is incomplete
  const RunState state =
      end_state == RunState::completed && !lossy.empty() ? RunState::incomplete : end_state;
  bin_run(store_, run_id_, config_.bin_s);
  for (const auto& slot : config_.slots) {
    try {
      const auto it = lossy.find(slot.serial);
      const auto part = options_.part_limits.find(slot.serial);
      const auto limits =
          part == options_.part_limits.end() ? std::nullopt : std::optional{part->second};
      compensation::ModelSpec paper;  // B0 + k1 dT + k0 gradT
      paper.ref_temp_c = config_.ref_temp_c;
      const auto f = fit_serial_for_part(
          store_, slot.serial, {run_id_}, paper, limits, false,
          it == lossy.end() ? std::vector<std::string>{} : std::vector{it->second});
      std::string coefs;  // by name: a part's model may lack k1 or k0, or order them otherwise
      for (std::size_t i = 1; i < f.fit.names.size(); ++i) {
        const std::string_view unit = compensation::coefficient_unit(f.fit.names[i]);
        coefs += fmt::format("{} {:.4e} {}, ", f.fit.names[i], f.fit.coefficients[i],
                             unit.substr(0, unit.find(" (")));  // "deg/h/C", as it always read
      }
      emit(t_s, Severity::info, "seq", EventKind::fit,
           fmt::format("{}: {}std ratio {} over {} bins", slot.serial, coefs,
                       std_ratio_text(f.eval), f.fit.n_points),
           {{"serial", slot.serial}});
      judge(t_s, f);
    } catch (const InputError& e) {
      emit(t_s, Severity::warn, "seq", EventKind::fit_skipped, e.what());
    }
  }
  record_acceptance_at_end(store_, run_id_, options_.part_limits);  // a failure only logged
  store_.finish_run(run_id_, state);
  emit(t_s, Severity::info, "seq", EventKind::run_end,
       fmt::format("run {} {}", run_id_, to_string(state)), {{"state", to_string(state)}});
  return state;
}

RunState Sequencer::abort(double t_s) {
  rest_table(t_s);
  drive_outputs(t_s, SafetyOutputs{});  // gyro power off, lamps dark
  for (const auto& o : outages_.close_all(t_s))
    emit(t_s, Severity::warn, o.device, EventKind::outage,
         fmt::format("still down when the run was aborted: {} lost ticks since t = {:.0f} s ({})",
                     o.ticks_lost, o.start_s, o.error),
         outage_json(o, OutageEnd::abort));
  store_.finish_run(run_id_, RunState::aborted);
  emit(t_s, Severity::warn, "seq", EventKind::run_end,
       fmt::format("run {} aborted (no bins, no fit)", run_id_),
       {{"state", to_string(RunState::aborted)}});
  return RunState::aborted;
}

void Sequencer::judge(double t_s, const SerialFit& f) {
  const auto it = options_.part_limits.find(f.serial);
  if (it == options_.part_limits.end()) return;
  const auto j = judge_and_store(store_, f, it->second);
  emit(t_s, j.verdict->pass ? Severity::info : Severity::warn, "seq", EventKind::verdict,
       fmt::format("{}: {}", f.serial, verdict_text(j.verdict)), verdict_json(*j.verdict));
}

void Sequencer::save_parts() {
  std::vector<SlotPart> parts;
  for (const auto& [serial, limits] : options_.part_limits)
    parts.push_back({serial, limits.number, part_limits_json(limits).dump()});
  if (!parts.empty()) save_run_parts(store_, run_id_, parts);
}

double Sequencer::resume_first_tick(const RunRecord& resume) {
  const double period = options_.period_s;
  const double last_s = resume.last_tick_s.value_or(-period);
  double t_first = last_s + period;
  if (options_.replay_until_t_s) {
    // A simulation replays deterministically from t = 0; ticks up to the last committed one are
    // recomputed, not stored again.
    t_first = 0;
  } else {
    // Real hardware: continue the protocol at the real elapsed time, so the outage shows as a
    // gap (incomplete bins), not as continuous data; but always strictly after the last
    // committed tick, whatever the wall clock did while the daemon was down (a step backwards
    // must not land on stored ticks).
    const double elapsed_s = drivers::tap_wall_time_s() - resume.t0_wall_s;
    if (options_.resume_at_t_s)
      t_first = std::max(t_first, *options_.resume_at_t_s);
    else if (std::isfinite(elapsed_s))
      t_first = std::max(t_first, std::floor(elapsed_s / period) * period);
    if (t_first > last_s + period) {
      emit(last_s, Severity::warn, "seq", EventKind::resume_gap,
           fmt::format("no samples from t = {:.0f} s to {:.0f} s (daemon down)", last_s, t_first),
           {{"from_s", last_s}, {"to_s", t_first}});
    }
  }
  if (!options_.replay_until_t_s) restore_outages(resume.id, last_s);
  emit(std::max(last_s, 0.0), Severity::warn, "seq", EventKind::resume,
       fmt::format("resuming run {} at step {} after t = {:.0f} s (next tick t = {:.0f} s)",
                   run_id_, resume.progress.step_index, last_s, t_first),
       {{"step_index", resume.progress.step_index}, {"last_s", last_s}, {"next_s", t_first}});
  if (options_.on_resume) options_.on_resume(last_s, t_first);
  return t_first;
}

void Sequencer::restore_outages(std::int64_t run_id, double last_s) {
  for (const auto& e : store_.open_outages(run_id)) {
    Outage o;
    o.device = e.device;
    o.start_s = e.start_s;
    // Every stored tick from its start to the last one lost the device.
    o.ticks_lost =
        std::max<std::int64_t>(1, std::llround((last_s - e.start_s) / options_.period_s) + 1);
    o.error = e.error;
    outages_.restore(std::move(o));
  }
}

// A new run: the protocol's step times checked before the run exists, the run stored, its
// parts, the start event.
void Sequencer::create_run() {
  // A ramp that would take longer than any step may is refused before the run exists.
  protocol_.check_step_times(config_.limits.min_setpoint_c, config_.limits.max_setpoint_c);
  check_acceptance_rig(protocol_, config_, rig_.turntable != nullptr);
  RunInfo info{protocol_.name,
               protocol_.text,
               config_.text,
               STATION_VERSION,
               config_.name,
               options_.operator_name,
               options_.sim_seed,
               drivers::tap_wall_time_s(),
               resolved_meaning_json(config_)};
  run_id_ = store_.create_run(info, run_slots_of(config_));
  save_parts();
  emit(0, Severity::info, "seq", EventKind::run_start,
       fmt::format("run {} protocol '{}' with {} gyros", run_id_, protocol_.name,
                   config_.slots.size()),
       {{"protocol", protocol_.name}, {"gyros", config_.slots.size()}});
}

RunOutcome Sequencer::run(const std::optional<RunRecord>& resume) {
  // Real hardware resumes at the stored protocol position; a simulation replays from t = 0.
  RunProgress progress = resume && !options_.replay_until_t_s ? resume->progress : RunProgress{};
  double t_first = 0;
  if (resume) {
    run_id_ = resume->id;
    t_first = resume_first_tick(*resume);
  } else {
    create_run();
  }
  // The safety layer's limits apply to the whole protocol before anything moves.
  std::vector<std::string> notes;
  protocol_ = safety_.clamp_protocol(protocol_, notes, rig_.chamber->controller_ramp());
  if (!resume) {
    for (const auto& n : notes) emit(0, Severity::warn, "safety", EventKind::clamp, n);
  }
  runner_.emplace(protocol_, progress);
  if (options_.on_run_start) options_.on_run_start(run_id_, protocol_, run_slots_of(config_));
  if (!options_.http_url.empty())
    emit(t_first, Severity::info, "http", EventKind::listen,
         fmt::format("live page at {}", options_.http_url), {{"url", options_.http_url}});
  connect_devices();
  return guarded_tick_loop(t_first);
}

// The tick loop; when the store cannot record (disk full, a file size limit, an I/O error)
// nothing this run measures from now on would be kept, so the rig goes to the state a run's end
// leaves it in (gyro power off, lamps dark) and the caller decides (serve closes the run once
// writing works again; run exits and the run stays resumable).
RunOutcome Sequencer::guarded_tick_loop(double t_first) {
  try {
    return tick_loop(t_first);
  } catch (const SqliteError& e) {
    log("seq")->error("run {}: the store failed: {}", run_id_, e.what());
    try {
      drive_outputs(last_t_s_, SafetyOutputs{});
    } catch (const std::exception& e2) {  // an event about the outputs may fail to store as well
      log("seq")->error("run {}: outputs after the store failed: {}", run_id_, e2.what());
    }
    throw;
  }
}

void Sequencer::note_tick_gap(double t_s, std::int64_t skipped) {
  const double period = options_.period_s;
  const double from_s = t_s - static_cast<double>(skipped) * period;
  log("seq")->warn("overrun: {} tick(s) skipped at t_s={:.0f}", skipped, t_s);
  rig_.counters->note_skipped_ticks(static_cast<int>(skipped));  // next delta spans them
  // In the record, like an outage: which ticks are missing, and why (the process was stopped
  // or starved; absolute deadlines skip late ticks, they never shift the schedule).
  emit(t_s, Severity::warn, "seq", EventKind::tick_gap,
       fmt::format("{} tick(s) missed from t = {:.0f} s to {:.0f} s (the daemon was late)", skipped,
                   from_s, t_s - period),
       {{"start_s", from_s}, {"end_s", t_s - period}, {"ticks_lost", skipped}});
}

RunOutcome Sequencer::tick_loop(double t_first) {
  const double period = options_.period_s;
  const double start = clock_.now_s();
  std::int64_t ticks = 0;
  for (std::int64_t k = 0;; ++k) {
    const double deadline = start + static_cast<double>(k) * period;
    std::int64_t skipped = 0;
    if (k > 0) {
      // Wait for tick k's deadline (at once when it has passed). A tick whose slot is over when
      // the wait ends (the process was stopped or starved) is skipped, never run late under its
      // own time: absolute deadlines, the schedule never shifts.
      watch_inputs_until(deadline, t_first + static_cast<double>(k - 1) * period);
      const auto due = static_cast<std::int64_t>(std::floor((clock_.now_s() - start) / period));
      if (due > k) {
        skipped = due - k;
        k = due;
      }
    }
    const double t_s = t_first + static_cast<double>(k) * period;
    last_t_s_ = t_s;
    replaying_ = options_.replay_until_t_s && t_s <= *options_.replay_until_t_s;
    if (skipped > 0) note_tick_gap(t_s, skipped);
    if (options_.before_tick) {
      Stopwatch timer(&phase_s_.world);
      options_.before_tick(t_s);
    }
    TickData d;
    const auto w0 = std::chrono::steady_clock::now();
    tick(t_s, d);
    ++ticks;
    if (options_.watchdog) options_.watchdog();
    if (options_.on_tick) {
      TickReport r = report(t_s, d);
      r.tick_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      r.skipped = skipped;
      options_.on_tick(r);
    }
    if (auto end = end_of_run(t_s, ticks)) return *end;
  }
}

std::optional<RunOutcome> Sequencer::end_of_run(double t_s, std::int64_t ticks) {
  if (options_.abort != nullptr && options_.abort->load())
    return RunOutcome{run_id_, abort(t_s), t_s, ticks};
  if (options_.detach != nullptr && options_.detach->load()) {
    emit(t_s, Severity::info, "seq", EventKind::detach,
         fmt::format("run {} left resumable at t = {:.0f} s (service restart)", run_id_, t_s));
    return RunOutcome{run_id_, RunState::detached, t_s, ticks};
  }
  const bool stop = options_.stop != nullptr && options_.stop->load();
  if (!runner_->done() && !stop) return std::nullopt;
  const RunState state = runner_->done() ? RunState::completed : RunState::stopped;
  const double n = static_cast<double>(ticks) / 1e6;  // -> microseconds per tick
  log("seq")->info(
      "tick phases, mean us: world {:.0f} can {:.0f} chamber {:.0f} table {:.0f} gpio {:.0f} "
      "store {:.0f}",
      phase_s_.world / n, phase_s_.rig.can / n, phase_s_.rig.chamber / n, phase_s_.rig.table / n,
      phase_s_.rig.gpio / n, phase_s_.store / n);
  return RunOutcome{run_id_, finish(state, t_s), t_s, ticks};
}

}  // namespace station
