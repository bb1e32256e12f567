// The sequencer's tick: devices in, one stored transaction out, protocol and safety forward.
#include "station/daemon/sequencer.hpp"

#include <fmt/format.h>

#include <array>
#include <chrono>
#include <cmath>

#include "drivers/gpio/gpio_bank.hpp"
#include "station/common/logging.hpp"

namespace station {

namespace dr = station::drivers;

namespace {

/// Adds the wall time of its scope to a phase total.
class PhaseTimer {
 public:
  explicit PhaseTimer(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~PhaseTimer() {
    total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

Sequencer::Sequencer(const StationConfig& config, const Protocol& protocol, Rig& rig, Store& store,
                     dr::Clock& clock, SequencerOptions options)
    : config_(config),
      protocol_(protocol),
      rig_(rig),
      store_(store),
      clock_(clock),
      options_(std::move(options)),
      safety_(config.limits) {}

void Sequencer::emit(double t_s, const std::string& severity, const std::string& source,
                     const std::string& kind, const std::string& message,
                     const std::optional<std::string>& data_json) {
  if (replaying_) return;
  const auto lvl = severity == "error"  ? spdlog::level::err
                   : severity == "warn" ? spdlog::level::warn
                                        : spdlog::level::info;
  log(source)->log(lvl, "{} t_s={:.0f} run={} {}", kind, t_s, run_id_, message);
  store_.add_event(run_id_, t_s, severity, source, kind, message, data_json);
}

void Sequencer::connect_devices() {
  const auto has_line = [this](std::string_view role) {
    return rig_.gpio != nullptr && dr::gpio::find_role(rig_.gpio->config(), role) != nullptr;
  };
  has_gpio_interlock_ = has_line(dr::gpio::roles::interlock);
  has_gpio_estop_ = has_line(dr::gpio::roles::estop);
  if (auto r = rig_.chamber->connect(); !r)
    emit(0, "warn", "chamber", "connect", r.error().message);
  if (rig_.turntable) {
    if (auto r = rig_.turntable->connect(); !r)
      emit(0, "warn", "table", "connect", r.error().message);
  }
  if (rig_.gpio) {
    if (auto r = rig_.gpio->open(); !r) emit(0, "warn", "gpio", "open", r.error().message);
  }
}

void Sequencer::read_devices(double t_s, TickData& d) {
  // SYNC and collect before the Modbus reads. (Overlapping the boards' answers with the Modbus
  // reads measured slower on 2 cores: the simulators' threads compete for them.)
  std::optional<PhaseTimer> timer(std::in_place, phase_s_.can);
  auto counts = rig_.counters->tick(latch_seq_++);
  if (counts) d.counts = std::move(counts).value();
  note_counters(t_s, d, counts ? std::string() : counts.error().message);
  timer.emplace(phase_s_.chamber);
  auto chamber = rig_.chamber->read();
  if (chamber) d.chamber = chamber.value();
  note_link(t_s, "chamber", chamber.ok(), chamber ? std::string() : chamber.error().message);
  timer.emplace(phase_s_.table);
  if (rig_.turntable) {
    auto table = rig_.turntable->read();
    if (table) {
      d.table = table.value();
      d.table_interlock_open = d.table->interlock_open;
    }
    note_link(t_s, "turntable", table.ok(), table ? std::string() : table.error().message);
  }
  timer.emplace(phase_s_.gpio);
  read_gpio(t_s, d);
}

void Sequencer::note_link(double t_s, const std::string& device, std::optional<bool> answered,
                          const std::string& error) {
  const auto news = outages_.observe(device, t_s, answered, error);
  if (!news) return;
  const Outage& o = news->outage;
  switch (news->change) {
    case OutageChange::started:
      emit(t_s, "warn", device, "outage_start", fmt::format("not answering: {}", o.error));
      return;
    case OutageChange::ended:
      emit(t_s, "warn", device, "outage",
           fmt::format("back after {} lost ticks (down since t = {:.0f} s: {})", o.ticks_lost,
                       o.start_s, o.error),
           outage_json(o));
      return;
  }
}

void Sequencer::note_counters(double t_s, const TickData& d, const std::string& error) {
  bool any = false;
  if (d.counts)
    for (const auto& r : d.counts->readings) any = any || r.answered;
  note_link(t_s, "can", any, d.counts ? "no counter board answered" : error);
  for (std::size_t i = 0; i < config_.slots.size(); ++i) {
    const std::string device = fmt::format("can node {}", config_.slots[i].node);
    // Behind a lost bus a board has no news of its own: the bus outage covers it.
    const auto* r = any ? &d.counts->readings[i] : nullptr;
    note_link(t_s, device, r ? std::optional<bool>(r->answered) : std::nullopt,
              "no complete answer to the latch");
    if (r == nullptr || !r->answered) continue;
    switch (r->chain) {
      case dr::counters::LatchChain::reset:
        emit(t_s, "warn", device, "board_reset",
             fmt::format("{}: counters restarted (reset flag, or counts or board clock went "
                         "backwards): re-baselined, no rate for this latch",
                         r->serial));
        break;
      case dr::counters::LatchChain::unproven:
        emit(t_s, "warn", device, "counts_rebaselined",
             fmt::format("{}: board clock disagrees with the time since its last good latch: "
                         "continuity unproven, re-baselined, no rate for this latch",
                         r->serial));
        break;
      case dr::counters::LatchChain::first:
      case dr::counters::LatchChain::continuous:
        break;
    }
  }
}

std::map<std::string, std::string> Sequencer::close_outages(double t_s) {
  for (const auto& o : outages_.close_all(t_s)) {
    emit(t_s, "error", o.device, "outage",
         fmt::format("still down at the end of the run: {} lost ticks since t = {:.0f} s ({})",
                     o.ticks_lost, o.start_s, o.error),
         outage_json(o));
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
    emit(t_s, "warn", "seq", "incomplete", out[slot.serial]);
  }
  return out;
}

void Sequencer::read_gpio(double t_s, TickData& d) {
  if (!rig_.gpio) return;
  if (auto ev = rig_.gpio->read_events(); ev) {
    for (const auto& e : ev.value()) {
      emit(t_s, "info", "gpio", "edge",
           fmt::format("{} {}", e.role, e.rising ? "rising" : "falling"));
    }
  }
  if (auto closed = rig_.gpio->read(dr::gpio::roles::interlock); closed) {
    d.gpio_interlock_closed = closed.value();
  }
  if (auto pressed = rig_.gpio->read(dr::gpio::roles::estop); pressed) {
    d.gpio_estop_pressed = pressed.value();
  }
}

void Sequencer::assemble_samples(double t_s, TickData& d) {
  const bool recording = runner_->progress().recording;
  d.obs.t_s = t_s;
  d.obs.has_turntable = rig_.turntable != nullptr;
  if (d.table) {
    d.obs.table_in_position = d.table->in_position;
    d.obs.table_angle_deg = d.table->angle_deg;
    d.obs.table_locked = d.table->locked;
  }
  if (d.chamber && std::isfinite(d.chamber->air_c)) d.obs.air_c = d.chamber->air_c;
  if (d.obs.air_c) last_air_c_ = d.obs.air_c;
  for (const auto& slot : config_.slots) {
    SampleRow r;
    r.serial = slot.serial;
    r.t_s = t_s;
    r.recording = recording;
    r.air_c = d.obs.air_c;
    if (d.chamber) r.setpoint_c = d.chamber->setpoint_c;
    r.flags = (d.chamber ? 0 : kChamberMissing) | (safety_.holding() ? kSafeHold : 0);
    const dr::counters::CounterReading* rd = nullptr;
    if (d.counts) {
      for (const auto& x : d.counts->readings) rd = x.serial == slot.serial ? &x : rd;
    }
    if (rd == nullptr || !rd->answered) r.flags |= kLatchLost;
    if (rd != nullptr && rd->answered && rd->has_delta) {
      r.net_pulses = rd->net_pulses;
      r.interval_s = rd->interval_s;
      r.rate_dph = rd->rate_dph;
    }
    if (rd != nullptr && rd->temps_c.size() >= 2 && std::isfinite(rd->temps_c[0]) &&
        std::isfinite(rd->temps_c[1])) {
      r.temp_c = rd->temps_c[0];
      r.temp2_c = rd->temps_c[1];
      d.obs.gyro_temps_c.push_back(rd->temps_c[0]);
    } else {
      r.flags |= kTempsMissing;
    }
    if (rd != nullptr && rd->status_flags != 0) r.flags |= kBoardFault;
    d.rows.push_back(std::move(r));
  }
}

void Sequencer::apply_safety(double t_s, TickData& d) {
  // Each source keeps its last known value when a read fails; the hold is cleared only on
  // positive readings, and inputs unreadable for kSafetyBlindTicks count as open.
  constexpr int kSafetyBlindTicks = 5;
  const bool has_table = rig_.turntable != nullptr;
  const bool has_gpio = has_gpio_interlock_, has_estop = has_gpio_estop_;
  const bool blind = (has_table && !d.table_interlock_open) ||
                     (has_gpio && !d.gpio_interlock_closed) || (has_estop && !d.gpio_estop_pressed);
  safety_blind_ticks_ = blind ? safety_blind_ticks_ + 1 : 0;
  if (safety_blind_ticks_ == kSafetyBlindTicks) {
    emit(t_s, "error", "safety", "inputs_unreadable",
         fmt::format("interlock / e-stop unreadable for {} ticks: treated as open",
                     kSafetyBlindTicks));
  }
  bool interlock = d.table_interlock_open.value_or(has_table && interlock_open_);
  if (d.gpio_interlock_closed)
    interlock = interlock || !*d.gpio_interlock_closed;
  else if (has_gpio)
    interlock = interlock || interlock_open_;
  // The chamber's own door switch counts as an interlock; its high-limit trip as an e-stop.
  if (d.chamber) interlock = interlock || d.chamber->alarms.door_open;
  bool estop = d.gpio_estop_pressed.value_or(estop_);
  if (d.chamber) estop = estop || d.chamber->alarms.high_limit_trip;
  if (safety_blind_ticks_ >= kSafetyBlindTicks) interlock = true;
  interlock_open_ = interlock;
  estop_ = estop;
  const bool was_holding = safety_.holding();
  const auto change = safety_.update(interlock, estop, safety_.judge(d.chamber));
  if (change && safety_.holding() && !was_holding) enter_safe_hold(t_s, d, *change);
  if (change && safety_.holding() && was_holding)
    emit(t_s, "error", "safety", "safe_hold_changed", *change);
  if (safety_.holding()) keep_safe_hold(t_s, d);
  drive_lamps(t_s);
  if (change && was_holding && !safety_.holding()) {
    emit(t_s, "info", "safety", "safe_hold_cleared", *change + ": resuming the protocol step");
    runner_->reenter(hold_air_c_);
  }
}

void Sequencer::watch_inputs_until(double deadline_s, double t_s) {
  const int fd = rig_.gpio ? rig_.gpio->event_fd() : -1;
  // Between ticks the loop waits on the GPIO bank's event fd: an interlock opening or an e-stop
  // puts the rig in safe hold at once, not at the next tick. Clearing waits for a tick.
  while (fd >= 0 && clock_.wait_readable(fd, deadline_s)) {
    TickData d;
    read_gpio(t_s, d);
    const bool open = d.gpio_interlock_closed && !*d.gpio_interlock_closed;
    const bool pressed = d.gpio_estop_pressed.value_or(false);
    if (safety_.holding() || !(open || pressed)) continue;
    interlock_open_ = interlock_open_ || open;
    estop_ = estop_ || pressed;
    const auto change = safety_.update(interlock_open_, estop_);
    d.obs.air_c = last_air_c_;
    if (change && safety_.holding()) {
      enter_safe_hold(t_s, d, *change + " (between ticks)");
      keep_safe_hold(t_s, d);
    }
  }
  clock_.sleep_until(deadline_s);
}

void Sequencer::enter_safe_hold(double t_s, const TickData& d, const std::string& why) {
  emit(t_s, "error", "safety", "safe_hold",
       why + ": chamber held at its air temperature, turntable stopped");
  pending_chamber_.reset();  // nothing the protocol asked for goes out during the hold
  pending_table_.reset();
  hold_air_c_ = d.obs.air_c;
  hold_commanded_ = false;
  table_stopped_ = rig_.turntable == nullptr;
}

void Sequencer::keep_safe_hold(double t_s, const TickData& d) {
  // Retried every tick until the devices accept: the hold setpoint needs one air reading.
  if (!hold_air_c_) hold_air_c_ = d.obs.air_c;
  // Someone else wrote the setpoint during the hold: the hold is written again.
  if (d.chamber && !(d.chamber->setpoint_c >= config_.limits.min_setpoint_c &&
                     d.chamber->setpoint_c <= config_.limits.max_setpoint_c))
    hold_commanded_ = false;
  if (!hold_commanded_ && hold_air_c_) {
    const auto r = rig_.chamber->command(safety_.hold_command(*hold_air_c_));
    hold_commanded_ = r.ok();
    if (!r && command_failures_++ % 60 == 0)
      emit(t_s, "error", "chamber", "hold_failed", r.error().message);
  }
  if (!table_stopped_) {
    const auto r = rig_.turntable->stop();
    table_stopped_ = r.ok();
    if (!r && command_failures_++ % 60 == 0)
      emit(t_s, "error", "table", "stop_failed", r.error().message);
  }
}

void Sequencer::drive_lamps(double t_s) {
  if (!rig_.gpio) return;
  // Red: a fault (e-stop, readings out of limits); amber: safe hold; green: running.
  const bool red = safety_.limits_fault() || estop_;
  const bool amber = safety_.holding() && !red, green = !safety_.holding();
  const std::array<std::pair<std::string_view, bool>, 3> lamps{
      {{dr::gpio::roles::tower_red, red},
       {dr::gpio::roles::tower_amber, amber},
       {dr::gpio::roles::tower_green, green}}};
  for (std::size_t i = 0; i < lamps.size(); ++i) {
    const auto& [role, on] = lamps[i];
    if (lamps_[i] == on || dr::gpio::find_role(rig_.gpio->config(), role) == nullptr) continue;
    if (auto r = rig_.gpio->write(role, on); r) {
      lamps_[i] = on;
    } else if (command_failures_++ % 60 == 0) {
      emit(t_s, "warn", "gpio", "lamp_failed", r.error().message);
    }
  }
}

void Sequencer::apply_actions(double t_s, const Actions& a) {
  for (const auto& e : a.events) emit(t_s, e.severity, "seq", e.kind, e.message);
  if (a.chamber) {
    std::vector<std::string> notes;
    pending_chamber_ = safety_.clamp(*a.chamber, notes);
    for (const auto& n : notes) emit(t_s, "warn", "safety", "clamp", n);
  }
  if (a.table) pending_table_ = a.table;
  // Commands are retried every tick until the device accepts them.
  if (pending_chamber_) {
    if (auto r = rig_.chamber->command(*pending_chamber_); r) {
      pending_chamber_.reset();
      command_failures_ = 0;
    } else if (command_failures_++ % 60 == 0) {
      emit(t_s, "warn", "chamber", "command_failed", r.error().message);
    }
  }
  if (pending_table_ && rig_.turntable) {
    if (auto r = rig_.turntable->command(*pending_table_); r) {
      pending_table_.reset();
    } else if (command_failures_++ % 60 == 0) {
      emit(t_s, "warn", "table", "command_failed", r.error().message);
    }
  }
}

void Sequencer::tick(double t_s, TickData& d) {
  read_devices(t_s, d);
  assemble_samples(t_s, d);
  apply_safety(t_s, d);
  Actions a;
  if (!safety_.holding()) a = runner_->tick(d.obs);
  apply_actions(t_s, a);
  if (!replaying_) {
    PhaseTimer timer(phase_s_.store);
    store_.append_tick(run_id_, t_s, d.rows, runner_->progress());
  }
}

}  // namespace station
