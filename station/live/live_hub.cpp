// The live hub: tick/event/run news in, status JSON and stream messages out.
#include "station/live/live_hub.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>

namespace station::live {

namespace {

constexpr std::size_t kTrendMax = 2000;    // points the page's temperature chart holds
constexpr std::size_t kMessagesMax = 512;  // stream messages kept for slow readers
constexpr std::size_t kEventsMax = 50;     // latest events in /api/live
constexpr auto kTickMessageGap = std::chrono::milliseconds(100);  // <= 10 tick messages / s

nlohmann::json num(const std::optional<double>& v) {
  return v && std::isfinite(*v) ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

nlohmann::json opt_bool(const std::optional<bool>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

nlohmann::json chamber_json(const std::optional<drivers::ChamberState>& c) {
  if (!c) return nullptr;
  return {{"air_c", num(c->air_c)},
          {"setpoint_c", num(c->setpoint_c)},
          {"mode", drivers::to_string(c->mode)},
          {"alarm", c->alarms.any()}};
}

nlohmann::json table_json(const std::optional<drivers::TurntableState>& t) {
  if (!t) return nullptr;
  return {{"angle_deg", t->angle_deg},
          {"rate_dps", t->rate_dps},
          {"locked", t->locked},
          {"mode", drivers::to_string(t->mode)}};
}

nlohmann::json bin_json(const LiveBin& b) {
  return {{"t_mid_s", b.t_mid_s},   {"temp_c", b.temp_c}, {"grad_c", b.grad_c},
          {"bias_dph", b.bias_dph}, {"n", b.n},           {"complete", b.complete}};
}

nlohmann::json safety_json(bool safe_hold, std::optional<bool> door_closed,
                           std::optional<bool> estop_pressed,
                           std::optional<bool> table_interlock_open) {
  return {{"safe_hold", safe_hold},
          {"door_closed", opt_bool(door_closed)},
          {"estop_pressed", opt_bool(estop_pressed)},
          {"table_interlock_open", opt_bool(table_interlock_open)}};
}

/// The protocol's steps as the page lists them: what each does, its target and how long it
/// nominally takes (Protocol::nominal_step_durations_s; a `to_start` target is known once the
/// run's start temperature is).
nlohmann::json steps_json(const Protocol& p, std::optional<double> start_c) {
  const auto durations = p.nominal_step_durations_s(start_c);
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < p.steps.size(); ++i) {
    const Step& s = p.steps[i];
    nlohmann::json j{
        {"label", s.label}, {"kind", to_string(s.kind)}, {"duration_s", num(durations[i])}};
    if (s.kind == StepKind::set_temperature) {
      j["target_c"] = num(s.to_start ? start_c : s.setpoint_c);
      j["to_start"] = s.to_start;
      j["ramp_c_per_h"] = s.ramp_c_per_h;
    } else if (s.kind == StepKind::soak) {
      j["tolerance_c"] = s.tolerance_c;
    } else if (s.kind == StepKind::lock_turntable) {
      j["position_deg"] = s.position_deg;
    }
    out.push_back(std::move(j));
  }
  return out;
}

nlohmann::json event_json(const RunEvent& e) {
  return {{"id", e.id},          {"run_id", e.run_id},
          {"t_s", e.t_s},        {"severity", to_string(e.severity)},
          {"source", e.source},  {"kind", to_string(e.kind)},
          {"message", e.message}};
}

}  // namespace

LiveHub::LiveHub(StationInfo info) : info_(std::move(info)) {}

void LiveHub::set_http_url(const std::string& url) {
  std::lock_guard lock(mu_);
  http_url_ = url;
}

void attach(LiveHub& hub, SequencerOptions& o) {
  o.on_run_start = [&hub, prev = o.on_run_start, op = o.operator_name](
                       std::int64_t id, const Protocol& p, const std::vector<RunSlot>& slots) {
    if (prev) prev(id, p, slots);
    hub.run_started(id, p, op, slots);
  };
  o.on_tick = [&hub, prev = o.on_tick](const TickReport& r) {
    if (prev) prev(r);
    hub.tick(r);
  };
  o.on_event = [&hub, prev = o.on_event](const RunEvent& e) {
    if (prev) prev(e);
    hub.event(e);
  };
}

nlohmann::json LiveHub::slot_json(const SampleRow& s) const {
  const auto it = earth_rate_dph_.find(s.serial);
  std::optional<double> bias;
  const std::optional<double> grad = gradient_c(s);
  if (s.rate_dph && it != earth_rate_dph_.end()) bias = *s.rate_dph - it->second;
  return {{"serial", s.serial},
          {"bias_dph", num(bias)},
          {"temp_c", num(s.temp_c)},
          {"grad_c", num(grad)}};
}

void LiveHub::publish_state(std::int64_t run_id) {
  const std::string state = state_locked();
  if (state == published_state_ && run_id == published_run_) return;
  metrics_.set_state(state, run_id);
  published_state_ = state;
  published_run_ = run_id;
}

void LiveHub::run_started(std::int64_t run_id, const Protocol& protocol,
                          const std::string& operator_name, const std::vector<RunSlot>& slots) {
  std::lock_guard lock(mu_);
  earth_rate_dph_.clear();
  for (const auto& s : slots) earth_rate_dph_[s.serial] = s.earth_rate_dph;
  metrics_.set_slots(slots);
  run_id_ = last_run_id_ = run_id;
  operator_ = operator_name;
  protocol_ = protocol;
  last_.reset();
  last_rows_.clear();
  run_failure_.clear();
  trend_.clear();
  trend_stride_ = 1;
  trend_seen_ = 0;
  bins_.emplace(earth_rate_dph_, info_.bin_s);
  publish_state(run_id);
  publish("run", {{"run_id", run_id}, {"state", "running"}});
}

void LiveHub::tick(const TickReport& r) {
  if (r.replaying) return;  // a resumed simulation recomputing what is stored already
  std::lock_guard lock(mu_);
  metrics_.tick(r);
  ++ticks_;
  const bool changed = !last_ || last_->step_index != r.step_index ||
                       last_->safe_hold != r.safe_hold || last_->recording != r.recording;
  last_ = r;
  last_->rows = nullptr;
  if (r.rows != nullptr) last_rows_ = *r.rows;
  publish_state(r.run_id);
  // The trend: every trend_stride_-th tick; when full, every other point goes and the stride
  // doubles, so a 13 h run ends with <= 2000 evenly spaced points.
  if (trend_seen_++ % trend_stride_ == 0) {
    trend_.push_back(
        {r.t_s, r.chamber ? r.chamber->air_c : NAN, r.chamber ? r.chamber->setpoint_c : NAN});
    if (trend_.size() >= kTrendMax) {
      std::vector<std::array<double, 3>> kept;
      for (std::size_t i = 0; i < trend_.size(); i += 2) kept.push_back(trend_[i]);
      trend_ = std::move(kept);
      trend_stride_ *= 2;
    }
  }
  if (bins_ && r.rows != nullptr) {
    for (const auto& [serial, b] : bins_->add(*r.rows))
      publish("bin", {{"run_id", r.run_id}, {"serial", serial}, {"bin", bin_json(b)}});
  }
  const auto now = std::chrono::steady_clock::now();
  if (!changed && now - last_tick_msg_ < kTickMessageGap) return;
  last_tick_msg_ = now;
  nlohmann::json slots = nlohmann::json::array();
  for (const auto& s : last_rows_) {
    slots.push_back(slot_json(s));
  }
  publish(
      "tick",
      {{"t_s", r.t_s},
       {"state", state_locked()},
       {"step_index", r.step_index},
       {"step_label", r.step_label},
       {"recording", r.recording},
       {"safe_hold", r.safe_hold},
       {"air_c", num(r.chamber ? std::optional(r.chamber->air_c) : std::nullopt)},
       {"setpoint_c", num(r.chamber ? std::optional(r.chamber->setpoint_c) : std::nullopt)},
       {"target_c", num(r.target_c)},
       // Everything the page shows comes with each tick, so it is all of one time.
       {"chamber", chamber_json(r.chamber)},
       {"table", table_json(r.table)},
       {"safety", safety_json(r.safe_hold, r.door_closed, r.estop_pressed, r.table_interlock_open)},
       {"slots", slots}});
}

void LiveHub::event(const RunEvent& e) {
  std::lock_guard lock(mu_);
  // An outage the device itself ended (not one closed at a run's end or abort): schemas/events.md.
  if (e.kind == EventKind::outage && e.data.is_object() && e.data.value("ended", "") == "answered")
    metrics_.reconnect(e.source, e.data["end_s"].get<double>() - e.data["start_s"].get<double>());
  auto j = event_json(e);
  events_.push_back(j);
  if (events_.size() > kEventsMax) events_.pop_front();
  publish("event", j);
}

void LiveHub::run_ended(std::int64_t run_id, const std::string& state) {
  metrics_.set_slots({});  // a finished run's gyro series go (no stale values)
  std::lock_guard lock(mu_);
  run_id_.reset();
  last_run_id_ = run_id;
  if (state.rfind("failed", 0) == 0) run_failure_ = state;
  publish_state(run_id);
  publish("run", {{"run_id", run_id}, {"state", state}});
}

void LiveHub::idle(const IdleReading& r) {
  std::lock_guard lock(mu_);
  metrics_.io_errors(r.in.io_errors);
  if (r.in.chamber) metrics_.chamber(*r.in.chamber);
  idle_ = r;
  fault_ = r.fault;
  publish_state(last_run_id_.value_or(0));
}

std::string LiveHub::state_locked() const {
  if (run_id_) return last_ && last_->safe_hold ? "hold" : "running";
  return fault_.empty() && run_failure_.empty() ? "idle" : "fault";
}

nlohmann::json LiveHub::status_locked() const {
  nlohmann::json run = nullptr;
  if (run_id_) {
    run = {{"id", *run_id_},
           {"protocol", protocol_.name},
           {"operator", operator_},
           {"t_s", last_ ? nlohmann::json(last_->t_s) : nlohmann::json(nullptr)},
           {"step_index", last_ ? last_->step_index : 0},
           {"step_label", last_ ? last_->step_label : std::string()},
           {"recording", last_ && last_->recording},
           {"target_c", num(last_ ? last_->target_c : std::nullopt)},
           {"steps", steps_json(protocol_, last_ ? last_->start_temp_c : std::nullopt)}};
  }
  const bool live = run_id_ && last_;
  nlohmann::json slots = nlohmann::json::array();
  for (const auto& s : live ? last_rows_ : std::vector<SampleRow>{}) {
    auto j = slot_json(s);
    j["rate_dph"] = num(s.rate_dph);
    slots.push_back(std::move(j));
  }
  nlohmann::json j{
      {"state", state_locked()},
      {"station", info_.station},
      {"pid", static_cast<long>(::getpid())},  // who answers: `probe` checks it holds the rig
      {"sim", info_.sim},
      {"speed", num(info_.speed)},
      {"bin_s", info_.bin_s},
      {"http", http_url_},
      {"rig_slots", info_.rig_slots},
      {"run", run},
      {"chamber", chamber_json(live    ? last_->chamber
                               : idle_ ? idle_->in.chamber
                                       : std::nullopt)},
      {"table", table_json(live    ? last_->table
                           : idle_ ? idle_->in.table
                                   : std::nullopt)},
      {"slots", slots},
      {"safety", safety_json(live && last_->safe_hold,
                             live    ? last_->door_closed
                             : idle_ ? idle_->in.door_closed
                                     : std::nullopt,
                             live    ? last_->estop_pressed
                             : idle_ ? idle_->in.estop_pressed
                                     : std::nullopt,
                             live    ? last_->table_interlock_open
                             : idle_ ? idle_->in.table_interlock_open
                                     : std::nullopt)},
      {"ticks", ticks_},
      {"last_tick_ms", last_ ? nlohmann::json(last_->tick_wall_s * 1e3) : nlohmann::json(nullptr)},
      {"last_run_id", last_run_id_ ? nlohmann::json(*last_run_id_) : nlohmann::json(nullptr)},
      {"fleet", fleet_}};
  if (!fault_.empty() || !run_failure_.empty())
    j["fault"] = run_failure_.empty() ? fault_
                 : fault_.empty()     ? run_failure_
                                      : run_failure_ + "; " + fault_;
  return j;
}

// A `fleet` stream message when the forwarder's state changes, not for the time of each pass.
void LiveHub::fleet(const nlohmann::json& forwarder) {
  const auto without_time = [](nlohmann::json j) {
    if (j.is_object()) {
      j.erase("last_success_unix_s");
      j.erase("waiting_s");  // a wait's seconds: in /api/status, not a message each second
    }
    return j;
  };
  std::lock_guard lock(mu_);
  const bool changed = without_time(forwarder) != without_time(fleet_);
  fleet_ = forwarder;
  if (changed) publish("fleet", fleet_);
}

nlohmann::json LiveHub::status() const {
  std::lock_guard lock(mu_);
  return status_locked();
}

nlohmann::json LiveHub::live() const {
  std::lock_guard lock(mu_);
  nlohmann::json trend = nlohmann::json::array();
  for (const auto& p : trend_) trend.push_back({p[0], num(p[1]), num(p[2])});
  nlohmann::json bins = nlohmann::json::object();
  if (bins_) {
    for (const auto& [serial, list] : bins_->bins()) {
      auto& a = bins[serial] = nlohmann::json::array();
      for (const auto& b : list) a.push_back(bin_json(b));
    }
  }
  nlohmann::json events = nlohmann::json::array();
  for (const auto& e : events_) events.push_back(e);
  return {{"status", status_locked()},
          {"trend", trend},
          {"bins", bins},
          {"events", events},
          {"seq", next_id_ - 1}};
}

std::optional<nlohmann::json> LiveHub::live_bins(std::int64_t run_id) const {
  std::lock_guard lock(mu_);
  if (!bins_ || last_run_id_ != run_id) return std::nullopt;
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [serial, list] : bins_->bins()) {
    auto& a = out[serial] = nlohmann::json::array();
    for (const auto& b : list) a.push_back(bin_json(b));
  }
  return out;
}

std::optional<std::int64_t> LiveHub::current_run() const {
  std::lock_guard lock(mu_);
  return run_id_;
}

void LiveHub::publish(const std::string& event, const nlohmann::json& data) {
  StreamMessage m;
  m.id = next_id_++;
  // One data line: dump() escapes newlines inside strings, so the JSON never splits the frame.
  m.text = fmt::format("id: {}\nevent: {}\ndata: {}\n\n", m.id, event,
                       data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  messages_.push_back(std::move(m));
  if (messages_.size() > kMessagesMax) messages_.pop_front();
  cv_.notify_all();
}

bool LiveHub::wait(std::uint64_t after_id, std::vector<StreamMessage>& out,
                   std::chrono::milliseconds timeout) {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, timeout, [&] { return closed_ || next_id_ - 1 > after_id; });
  if (closed_) return false;
  if (!messages_.empty() && messages_.front().id > after_id + 1) {
    // Fell behind the buffer: the page reloads /api/live rather than miss a bin or an event.
    out.push_back({messages_.front().id - 1,
                   fmt::format("id: {}\nevent: resync\ndata: {{}}\n\n", messages_.front().id - 1)});
  }
  for (const auto& m : messages_)
    if (m.id > after_id) out.push_back(m);
  return true;
}

std::uint64_t LiveHub::last_id() const {
  std::lock_guard lock(mu_);
  return next_id_ - 1;
}

void LiveHub::close() {
  std::lock_guard lock(mu_);
  closed_ = true;
  cv_.notify_all();
}

}  // namespace station::live
