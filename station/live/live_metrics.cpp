// Metric definitions and their updates from tick reports.
#include "station/live/live_metrics.hpp"

#include <prometheus/text_serializer.h>

#include <cmath>
#include <sstream>

#include "compensation/earth_rate.hpp"
#include "station/store/store.hpp"

namespace station::live {

namespace pm = prometheus;

namespace {

pm::Family<pm::Counter>& counter(pm::Registry& r, const std::string& name,
                                 const std::string& help) {
  return pm::BuildCounter().Name(name).Help(help).Register(r);
}

pm::Family<pm::Gauge>& gauge(pm::Registry& r, const std::string& name, const std::string& help) {
  return pm::BuildGauge().Name(name).Help(help).Register(r);
}

const char* const kStates[] = {"idle", "running", "hold", "fault"};

}  // namespace

LiveMetrics::LiveMetrics()
    : registry_(std::make_shared<pm::Registry>()),
      // Buckets around the 1 s period: a healthy tick takes milliseconds, 1 s is a missed one.
      tick_duration_(pm::BuildHistogram()
                         .Name("station_tick_duration_seconds")
                         .Help("Wall time of one tick: devices, safety, store")
                         .Register(*registry_)
                         .Add({}, pm::Histogram::BucketBoundaries{0.0001, 0.00025, 0.0005, 0.001,
                                                                  0.0025, 0.005, 0.01, 0.025, 0.05,
                                                                  0.1, 0.25, 0.5, 1.0})),
      ticks_(counter(*registry_, "station_ticks_total", "Ticks run").Add({})),
      missed_(counter(*registry_, "station_missed_ticks_total",
                      "Tick deadlines skipped because a tick overran")
                  .Add({})),
      device_errors_(counter(*registry_, "station_device_errors_total",
                             "Device reads that failed, by device and error kind")),
      reconnects_(counter(*registry_, "station_device_reconnects_total",
                          "Devices answering again after an outage")),
      outage_s_(counter(*registry_, "station_device_outage_seconds_total",
                        "Run time lost to ended device outages, by device")),
      safe_hold_(gauge(*registry_, "station_safe_hold", "1 while the rig is in safe hold").Add({})),
      air_c_(gauge(*registry_, "station_chamber_air_celsius", "Chamber air temperature").Add({})),
      setpoint_c_(
          gauge(*registry_, "station_chamber_setpoint_celsius", "Chamber setpoint").Add({})),
      table_rate_(
          gauge(*registry_, "station_table_rate_degrees_per_second", "Turntable rate").Add({})),
      samples_(counter(*registry_, "station_samples_stored_total", "Gyro samples stored").Add({})),
      run_state_(gauge(*registry_, "station_run_state", "1 for the station's current state")),
      run_id_(
          gauge(*registry_, "station_run_id", "Id of the current or last run (0: none)").Add({})),
      http_requests_(
          counter(*registry_, "station_http_requests_total", "HTTP requests by status code")),
      http_requests_by_route_(counter(*registry_, "station_http_route_requests_total",
                                      "HTTP requests by route and status code")),
      slot_rate_(gauge(*registry_, "station_gyro_rate_degrees_per_hour",
                       "Gyro rate of the last tick, by serial and CAN node")),
      slot_bias_(gauge(*registry_, "station_gyro_bias_degrees_per_hour",
                       "Gyro rate minus Earth rate along its axis, by serial and CAN node")),
      slot_temp_(gauge(*registry_, "station_gyro_temperature_celsius",
                       "Gyro temperature (first sensor), by serial and CAN node")),
      slot_grad_(gauge(*registry_, "station_gyro_gradient_celsius",
                       "Temperature gradient inside the gyro (second sensor minus first)")),
      slot_latch_lost_(counter(*registry_, "station_gyro_latch_lost_total",
                               "Ticks without the gyro's counter answer (CAN frames lost)")),
      stream_clients_(
          gauge(*registry_, "station_event_stream_clients", "Clients attached to the event stream")
              .Add({})) {
  // Every device's series exist from the start (at 0), so a scrape sees them before a fault.
  for (const char* device : {"chamber", "turntable", "can", "gpio"}) {
    reconnects_.Add({{"device", device}});
    outage_s_.Add({{"device", device}});
    for (const char* kind : {"timeout", "disconnected", "protocol"})
      device_errors_.Add({{"device", device}, {"kind", kind}});
  }
  set_state("idle", 0);
}

void LiveMetrics::tick(const TickReport& r) {
  tick_duration_.Observe(r.tick_wall_s);
  ticks_.Increment();
  missed_.Increment(static_cast<double>(r.skipped));
  io_errors(r.io_errors);
  safe_hold_.Set(r.safe_hold ? 1 : 0);
  if (r.chamber) chamber(*r.chamber);
  if (r.table) table_rate_.Set(r.table->rate_dps);
  if (r.rows == nullptr) return;
  samples_.Increment(static_cast<double>(r.rows->size()));
  std::lock_guard lock(slots_mu_);
  for (const SampleRow& row : *r.rows) {
    const auto it = slots_.find(row.serial);
    if (it == slots_.end()) continue;
    const auto& l = it->second.labels;
    if (row.rate_dph) {
      slot_rate_.Add(l).Set(*row.rate_dph);
      slot_bias_.Add(l).Set(compensation::bias_dph(*row.rate_dph, it->second.earth_rate_dph));
    }
    if (row.temp_c) slot_temp_.Add(l).Set(*row.temp_c);
    if (const auto g = gradient_c(row)) slot_grad_.Add(l).Set(*g);
    if ((row.flags & kLatchLost) != 0) slot_latch_lost_.Add(l).Increment();
  }
}

void LiveMetrics::set_slots(const std::vector<RunSlot>& slots) {
  std::lock_guard lock(slots_mu_);
  for (const auto& [serial, old] : slots_) {
    for (auto* f : {&slot_rate_, &slot_bias_, &slot_temp_, &slot_grad_})
      f->Remove(&f->Add(old.labels));
    slot_latch_lost_.Remove(&slot_latch_lost_.Add(old.labels));
  }
  slots_.clear();
  for (const auto& s : slots) {
    SlotLabels sl{{{"serial", s.serial}, {"node", std::to_string(s.node)}}, s.earth_rate_dph};
    slot_latch_lost_.Add(sl.labels);  // at 0 from the start, like the device series
    slots_[s.serial] = std::move(sl);
  }
}

void LiveMetrics::io_errors(const std::vector<IoError>& errors) {
  for (const auto& e : errors)
    device_errors_.Add({{"device", e.device}, {"kind", e.kind}}).Increment();
}

void LiveMetrics::chamber(const drivers::ChamberState& c) {
  air_c_.Set(c.air_c);
  setpoint_c_.Set(c.setpoint_c);
}

void LiveMetrics::set_state(const std::string& state, std::int64_t run_id) {
  for (const char* s : kStates) run_state_.Add({{"state", s}}).Set(state == s ? 1 : 0);
  run_id_.Set(static_cast<double>(run_id));
}

void LiveMetrics::reconnect(const std::string& device, double outage_s) {
  reconnects_.Add({{"device", device}}).Increment();
  if (std::isfinite(outage_s) && outage_s > 0)
    outage_s_.Add({{"device", device}}).Increment(outage_s);
}

void LiveMetrics::http_request(int status, const std::string& route) {
  http_requests_.Add({{"code", std::to_string(status)}}).Increment();
  http_requests_by_route_.Add({{"route", route}, {"code", std::to_string(status)}}).Increment();
}

void LiveMetrics::stream_clients(int n) {
  stream_clients_.Set(n);
}

std::string LiveMetrics::text() const {
  std::ostringstream out;
  pm::TextSerializer().Serialize(out, registry_->Collect());
  return out.str();
}

// Registered only on a station that forwards, so a scrape of one that does not shows no fleet.
// The state as one series per state, 1 for the current one (the Prometheus way of an enum).
void LiveMetrics::fleet(const FleetMetrics& f) {
  std::lock_guard lock(fleet_mu_);
  if (fleet_runs_ == nullptr) {
    auto& state = gauge(*registry_, "station_fleet_state",
                        "The fleet forwarder's state: 1 for the current one");
    for (const char* s : kFleetStates) fleet_states_.emplace_back(s, &state.Add({{"state", s}}));
    fleet_waiting_ = &gauge(*registry_, "station_fleet_waiting_seconds",
                            "How long the forwarder's call in flight has waited on the server "
                            "(0: none waiting)")
                          .Add({});
    fleet_runs_ = &gauge(*registry_, "station_fleet_pending_runs",
                         "Runs the fleet forwarder has not delivered in their latest state")
                       .Add({});
    fleet_rows_ = &gauge(*registry_, "station_fleet_pending_rows",
                         "Rows still to forward: items, and the events and samples behind them")
                       .Add({});
    fleet_success_ = &gauge(*registry_, "station_fleet_last_success_timestamp_seconds",
                            "Unix time of the last pass that reached the fleet server (0: none)")
                          .Add({});
    fleet_errors_ = &counter(*registry_, "station_fleet_errors_total",
                             "Forwarder failures: server unreachable or items refused")
                         .Add({});
  }
  for (auto& [name, g] : fleet_states_) g->Set(name == f.state ? 1 : 0);
  fleet_waiting_->Set(f.waiting_s);
  fleet_runs_->Set(static_cast<double>(f.pending_runs));
  fleet_rows_->Set(static_cast<double>(f.pending_rows));
  fleet_success_->Set(f.last_success_unix_s);
  if (f.errors_total > fleet_errors_seen_) {
    fleet_errors_->Increment(static_cast<double>(f.errors_total - fleet_errors_seen_));
    fleet_errors_seen_ = f.errors_total;
  }
}

}  // namespace station::live
