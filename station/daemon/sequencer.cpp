// The sequencer's tick: devices in, one stored transaction out, protocol and safety forward.
#include "station/daemon/sequencer.hpp"

#include <fmt/format.h>

#include <array>
#include <chrono>
#include <cmath>

#include "drivers/common/exchange_deadline.hpp"
#include "drivers/gpio/gpio_bank.hpp"
#include "station/common/logging.hpp"
#include "station/daemon/sample.hpp"
#include "station/daemon/stopwatch.hpp"
#include "station/daemon/time_left.hpp"

namespace station {

namespace dr = station::drivers;

namespace {

// Which safety inputs the rig has: each one configured must be readable every tick.
SafetySources sources_of(const Rig& rig) {
  const auto has_line = [&rig](std::string_view role) {
    return rig.gpio != nullptr && dr::gpio::find_role(rig.gpio->config(), role) != nullptr;
  };
  return {rig.turntable != nullptr, has_line(dr::gpio::roles::interlock),
          has_line(dr::gpio::roles::estop)};
}

}  // namespace

Sequencer::Sequencer(const StationConfig& config, const Protocol& protocol, Rig& rig, Store& store,
                     dr::Clock& clock, SequencerOptions options)
    : config_(config),
      protocol_(protocol),
      rig_(rig),
      store_(store),
      clock_(clock),
      options_(std::move(options)),
      safety_(config.limits, sources_of(rig)),
      setpoint_watch_(
          parse_foreign_setpoint(config.on_foreign_setpoint).value_or(ForeignSetpoint::restore)),
      outputs_(rig.gpio.get(), config.slots.size()) {}

void Sequencer::emit(double t_s, Severity severity, const std::string& source, EventKind kind,
                     const std::string& message, const nlohmann::json& data) {
  if (replaying_) return;
  const auto lvl = severity == Severity::error  ? spdlog::level::err
                   : severity == Severity::warn ? spdlog::level::warn
                                                : spdlog::level::info;
  log(source)->log(lvl, "{} t_s={:.0f} run={} {}", to_string(kind), t_s, run_id_, message);
  const auto id = store_.add_event(run_id_, t_s, severity, source, kind, message, data);
  if (options_.on_event)
    options_.on_event({id, run_id_, t_s, severity, source, kind, message, data});
}

void Sequencer::connect_devices() {
  if (auto r = rig_.chamber->connect(); !r)
    emit(0, Severity::warn, "chamber", EventKind::connect, r.error().message);
  if (rig_.turntable) {
    if (auto r = rig_.turntable->connect(); !r)
      emit(0, Severity::warn, "table", EventKind::connect, r.error().message);
  }
  if (rig_.gpio) {
    if (auto r = rig_.gpio->open(); !r)
      emit(0, Severity::warn, "gpio", EventKind::open, r.error().message);
  }
}

void Sequencer::read_devices(double t_s, TickData& d) {
  RigReadPlan plan{latch_seq_++};
  plan.budget_s = kTickReadBudgetS * options_.period_s;  // 0.6 s of the 1 s tick
  d.in = read_rig(rig_, plan, &phase_s_.rig);
  note_counters(t_s, d, d.in.counters_error ? d.in.counters_error->message : std::string());
  note_link(t_s, "chamber", d.in.chamber.has_value(),
            d.in.chamber_error ? d.in.chamber_error->message : std::string());
  if (d.in.has_table)
    note_link(t_s, "turntable", d.in.table.has_value(),
              d.in.table_error ? d.in.table_error->message : std::string());
  note_edges(t_s, d.in);
  screen(t_s, d);
}

void Sequencer::note_link(double t_s, const std::string& device, std::optional<bool> answered,
                          const std::string& error) {
  const auto news = outages_.observe(device, t_s, answered, error);
  if (!news) return;
  const Outage& o = news->outage;
  switch (news->change) {
    case OutageChange::started:
      emit(t_s, Severity::warn, device, EventKind::outage_start,
           fmt::format("not answering: {}", o.error), {{"device", device}, {"error", o.error}});
      return;
    case OutageChange::ended:
      emit(t_s, Severity::warn, device, EventKind::outage,
           fmt::format("back after {} lost ticks (down since t = {:.0f} s: {})", o.ticks_lost,
                       o.start_s, o.error),
           outage_json(o, OutageEnd::answered));
      return;
  }
}

void Sequencer::note_counters(double t_s, const TickData& d, const std::string& error) {
  bool any = false;
  const auto& counts = d.in.counters;
  if (counts)
    for (const auto& r : counts->readings) any = any || r.answered;
  note_link(t_s, "can", any, counts ? "no counter board answered" : error);
  for (std::size_t i = 0; i < config_.slots.size(); ++i) {
    const std::string device = fmt::format("can node {}", config_.slots[i].node);
    // Behind a lost bus a board has no news of its own: the bus outage covers it.
    const auto* r = any ? &counts->readings[i] : nullptr;
    note_link(t_s, device, r ? std::optional<bool>(r->answered) : std::nullopt,
              "no complete answer to the latch");
    if (r == nullptr || !r->answered) continue;
    switch (r->chain) {
      case dr::counters::LatchChain::reset:
        emit(t_s, Severity::warn, device, EventKind::board_reset,
             fmt::format("{}: counters restarted (reset flag, or counts or board clock went "
                         "backwards): re-baselined, no rate for this latch",
                         config_.slots[i].serial),
             {{"serial", config_.slots[i].serial}});
        break;
      case dr::counters::LatchChain::unproven:
        emit(t_s, Severity::warn, device, EventKind::counts_rebaselined,
             fmt::format("{}: board clock disagrees with the time since its last good latch: "
                         "continuity unproven, re-baselined, no rate for this latch",
                         config_.slots[i].serial),
             {{"serial", config_.slots[i].serial}});
        break;
      case dr::counters::LatchChain::first:
      case dr::counters::LatchChain::continuous:
        break;
    }
  }
}

std::map<std::string, std::string> Sequencer::close_outages(double t_s) {
  for (const auto& o : outages_.close_all(t_s)) {
    emit(t_s, Severity::error, o.device, EventKind::outage,
         fmt::format("still down at the end of the run: {} lost ticks since t = {:.0f} s ({})",
                     o.ticks_lost, o.start_s, o.error),
         outage_json(o, OutageEnd::run_end));
  }
  std::map<std::string, std::string> out;
  for (const auto& slot : config_.slots) {
    const auto loss =
        record_window_loss(store_.samples(run_id_, slot.serial, true), options_.period_s);
    if (loss.share() <= config_.max_lost_share) continue;
    out[slot.serial] = fmt::format(
        "run {} incomplete: {} has no rate for {} of its {} record-window ticks ({:.1f} %, "
        "max_lost_share {:.1f} %)",
        run_id_, slot.serial, loss.lost, loss.ticks, 100 * loss.share(),
        100 * config_.max_lost_share);
    emit(t_s, Severity::warn, "seq", EventKind::incomplete, out[slot.serial],
         {{"serial", slot.serial}, {"lost_ticks", loss.lost}, {"window_ticks", loss.ticks}});
  }
  return out;
}

void Sequencer::note_edges(double t_s, const RigReading& in) {
  for (const auto& e : in.edges) {
    emit(t_s, Severity::info, "gpio", EventKind::edge,
         fmt::format("{} {}", e.role, e.rising ? "rising" : "falling"),
         {{"role", e.role}, {"rising", e.rising}});
  }
}

void Sequencer::assemble_samples(double t_s, TickData& d) {
  const bool recording = runner_->progress().recording;
  d.obs.t_s = t_s;
  d.obs.has_turntable = rig_.turntable != nullptr;
  const auto& table = d.in.table;
  const auto& chamber = d.in.chamber;
  if (table) {
    d.obs.table_in_position = table->in_position;
    // An angle screened out (plausibility.cpp) is no position.
    if (std::isfinite(table->angle_deg)) d.obs.table_angle_deg = table->angle_deg;
    d.obs.table_locked = table->locked;
    if (std::isfinite(table->rate_dps)) d.obs.table_rate_dps = table->rate_dps;
  }
  // A sample of an acceptance step, or one taken while the table turns (a ladder's table still
  // slowing after its step ended): the rate holds the table's, no thermal bias. 0.001 deg/s is
  // 3.6 deg/h, hundreds of times a bias.
  constexpr double kTableStillDps = 1e-3;
  const bool turning = d.obs.table_rate_dps && std::abs(*d.obs.table_rate_dps) > kTableStillDps;
  const int step_flags = runner_->in_acceptance_step() || turning ? kAcceptanceStep : 0;
  d.obs.air_c = d.in.air_c();
  if (d.obs.air_c) last_air_c_ = d.obs.air_c;
  for (std::size_t i = 0; i < config_.slots.size(); ++i) {
    SampleRow r;
    r.serial = config_.slots[i].serial;
    r.t_s = t_s;
    r.recording = recording;
    r.air_c = d.obs.air_c;
    if (chamber && std::isfinite(chamber->setpoint_c)) r.setpoint_c = chamber->setpoint_c;
    r.flags = (chamber ? 0 : kChamberMissing) | (safety_.holding() ? kSafeHold : 0) | step_flags;
    const dr::counters::CounterReading* rd = nullptr;
    // The board of slot i (its node): the gyro on it is the run's (run_gyros.hpp), whatever
    // serial the rig was built with.
    if (d.in.counters && i < d.in.counters->readings.size()) rd = &d.in.counters->readings[i];
    apply_reading(rd, r);
    if (r.temp_c) d.obs.gyro_temps_c.push_back(*r.temp_c);
    d.rows.push_back(std::move(r));
  }
}

void Sequencer::apply_safety(double t_s, TickData& d) {
  check_setpoint(t_s, d);
  auto in = safety_inputs(d.in, d.obs.air_c);
  in.air_implausible = d.air_implausible;
  in.setpoint_foreign =
      setpoint_watch_.foreign() && setpoint_watch_.action() == ForeignSetpoint::hold;
  const auto decision = safety_.decide(in);
  act_on_safety(t_s, decision);
  if (decision.cleared) runner_->reenter(decision.hold_air_c);
}

void Sequencer::watch_inputs_until(double deadline_s, double t_s) {
  const int fd = rig_.gpio ? rig_.gpio->event_fd() : -1;
  // Between ticks the loop waits on the GPIO bank's event fd: an interlock opening or an e-stop
  // puts the rig in safe hold at once, not at the next tick. Clearing waits for a tick.
  while (fd >= 0 && clock_.wait_readable(fd, deadline_s)) {
    const RigReading in = read_rig(rig_, RigReadPlan{std::nullopt, false, false});
    note_edges(t_s, in);
    act_on_safety(t_s, safety_.decide_between_ticks(in.door_closed, in.estop_pressed, last_air_c_));
  }
  clock_.sleep_until(deadline_s);
}

void Sequencer::act_on_safety(double t_s, const SafetyDecision& d) {
  for (const auto& e : d.events) emit(t_s, "safety", e);
  // Nothing the protocol asked for goes out during the hold; a hold only for another master's
  // setpoint keeps it for when the chamber reads the station's value again.
  SafetyCauses foreign_only;
  foreign_only.setpoint_foreign = true;
  if (d.entered && !(safety_.causes() == foreign_only)) {
    pending_chamber_.reset();
    pending_table_.reset();
  }
  bool chamber_ok = false, table_ok = false;
  if (d.chamber) {
    const auto r = command_chamber(*d.chamber);
    chamber_ok = r.ok();
    if (!r && command_failures_++ % 60 == 0)
      emit(t_s, Severity::error, "chamber", EventKind::hold_failed, r.error().message);
  }
  if (d.stop_table && rig_.turntable) {
    const auto r = stop_table();
    table_ok = r.ok();
    if (!r && command_failures_++ % 60 == 0)
      emit(t_s, Severity::error, "table", EventKind::stop_failed, r.error().message);
  }
  safety_.acknowledge(chamber_ok, table_ok);
  drive_outputs(t_s, d.outputs);
}

void Sequencer::drive_outputs(double t_s, SafetyOutputs o) {
  // The gyros are powered when safety allows it and the protocol wants it (a power cycle's off
  // time, issue 36).
  if (runner_) o.gyro_power = o.gyro_power && runner_->gyro_power();
  for (const auto& failure : outputs_.write(o))
    if (command_failures_++ % 60 == 0)
      emit(t_s, Severity::warn, "gpio", EventKind::output_failed, failure);
}

void Sequencer::apply_actions(double t_s, const Actions& a) {
  for (const auto& e : a.events) emit(t_s, "seq", e);
  if (a.chamber) {
    std::vector<std::string> notes;
    pending_chamber_ = safety_.clamp(*a.chamber, notes);
    for (const auto& n : notes) emit(t_s, Severity::warn, "safety", EventKind::clamp, n);
  }
  if (a.table) {
    pending_table_ = a.table;
    if (a.table->lock) table_released_ = !*a.table->lock;
  }
  if (a.gyro_power && !safety_.holding()) drive_outputs(t_s, safety_.outputs());
  // Commands are retried every tick until the device accepts them; none while the rig holds
  // (one kept through a hold for a foreign setpoint waits for its end).
  if (safety_.holding()) return;
  if (pending_chamber_) {
    if (auto r = command_chamber(*pending_chamber_); r) {
      pending_chamber_.reset();
      command_failures_ = 0;
    } else if (command_failures_++ % 60 == 0) {
      emit(t_s, Severity::warn, "chamber", EventKind::command_failed, r.error().message);
    }
  }
  if (pending_table_ && rig_.turntable) {
    if (auto r = command_table(*pending_table_); r) {
      pending_table_.reset();
    } else if (command_failures_++ % 60 == 0) {
      emit(t_s, Severity::warn, "table", EventKind::command_failed, r.error().message);
    }
  }
}

TickReport Sequencer::report(double t_s, const TickData& d) const {
  TickReport r;
  r.t_s = t_s;
  r.step_index = runner_->progress().step_index;
  r.steps = static_cast<int>(protocol_.steps.size());
  if (r.step_index >= 0 && r.step_index < r.steps)
    r.step_label = protocol_.steps[static_cast<std::size_t>(r.step_index)].label;
  r.recording = runner_->progress().recording;
  r.target_c = runner_->setpoint_c();
  r.start_temp_c = runner_->progress().start_temp_c;
  r.time_left_s =
      station::time_left_s(protocol_, {r.step_index, t_s - runner_->progress().step_started_s,
                                       r.start_temp_c, runner_->ramp_point_c(), r.target_c});
  r.safe_hold = safety_.holding();
  r.air_c = d.obs.air_c;
  r.run_id = run_id_;
  r.chamber = d.in.chamber;
  r.table = d.in.table;
  r.door_closed = d.in.door_closed;
  r.estop_pressed = d.in.estop_pressed;
  r.table_interlock_open = d.in.table_interlock_open;
  r.rows = &d.rows;
  r.io_errors = d.in.io_errors;
  r.replaying = replaying_;
  return r;
}

void Sequencer::tick(double t_s, TickData& d) {
  {
    // One deadline for all of the tick's device I/O, reads and commands: every exchange ends by
    // it (the drivers take the scope), and a command whose turn comes after it is not sent. Only
    // on the wall clock: a simulated tick (SimClock: lockstep, replay) loses nothing to the wall
    // time its I/O takes, and a budget there would make the run depend on the machine's load.
    std::optional<dr::ExchangeDeadline> cap;
    if (dynamic_cast<const dr::MonotonicClock*>(&clock_) != nullptr) {
      const auto io_s = std::chrono::duration<double>(kTickIoShare * options_.period_s);
      io_end_ = std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(io_s);
      cap.emplace(*io_end_);
    }
    struct EndsWithTheScope {  // between ticks (and after a throw) no tick budget holds
      std::optional<std::chrono::steady_clock::time_point>& end;
      ~EndsWithTheScope() { end.reset(); }
    } window{io_end_};
    read_devices(t_s, d);
    assemble_samples(t_s, d);
    apply_safety(t_s, d);
    Actions a;
    if (!safety_.holding()) a = runner_->tick(d.obs);
    apply_actions(t_s, a);
  }
  if (!replaying_) {
    Stopwatch timer(&phase_s_.store);
    store_.append_tick(run_id_, t_s, d.rows, runner_->progress());
  }
}

}  // namespace station
