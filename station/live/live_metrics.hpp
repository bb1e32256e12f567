// The station's Prometheus metrics (prometheus-cpp core: registry and text serializer; the HTTP
// room serves them at /metrics). Names follow the Prometheus naming guide: base units (seconds,
// celsius), _total for counters. Thread-safe: metrics are atomics inside prometheus-cpp.
#pragma once

#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "station/daemon/sequencer.hpp"

namespace station::live {

/// The fleet forwarder's states (station/fleet/forwarder_thread.hpp, schemas/api.md).
inline constexpr const char* kFleetStates[] = {
    "starting", "idle", "sending", "waiting on server", "backing off", "refusing items"};

/// What /metrics shows of the fleet forwarder.
struct FleetMetrics {
  std::string state;
  double waiting_s = 0;
  std::int64_t pending_runs = 0, pending_rows = 0;
  double last_success_unix_s = 0;
  std::int64_t errors_total = 0;
};

/// Every metric of the station.
class LiveMetrics {
 public:
  LiveMetrics();
  /// One tick of a run (not one a resumed simulation recomputes).
  void tick(const TickReport& r);
  /// Device errors of an idle look (serve between runs).
  void io_errors(const std::vector<IoError>& errors);
  void chamber(const drivers::ChamberState& c);
  /// Run state gauge: exactly one of idle, running, hold, fault is 1.
  void set_state(const std::string& state, std::int64_t run_id);
  /// A device that answered again after an outage (an 'outage' event).
  void reconnect(const std::string& device, double outage_s);
  /// An HTTP request answered: by status and by route (a bounded set of labels: the HTTP
  /// service's route_label, "other" when no route was matched).
  void http_request(int status, const std::string& route = "other");
  /// The run's gyros: per-slot series labelled by serial and CAN node (old slots' series go).
  void set_slots(const std::vector<RunSlot>& slots);
  void stream_clients(int n);
  /// The fleet forwarder ([fleet]): its state, the wait in flight, backlog, last success (Unix
  /// s, 0: none), failures so far.
  void fleet(const FleetMetrics& f);
  /// The exposition text (format 0.0.4).
  std::string text() const;

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Histogram& tick_duration_;
  prometheus::Counter& ticks_;
  prometheus::Counter& missed_;
  prometheus::Family<prometheus::Counter>& device_errors_;
  prometheus::Family<prometheus::Counter>& reconnects_;
  prometheus::Family<prometheus::Counter>& outage_s_;
  prometheus::Gauge& safe_hold_;
  prometheus::Gauge& air_c_;
  prometheus::Gauge& setpoint_c_;
  prometheus::Gauge& table_rate_;
  prometheus::Counter& samples_;
  prometheus::Family<prometheus::Gauge>& run_state_;
  prometheus::Gauge& run_id_;
  prometheus::Family<prometheus::Counter>& http_requests_;
  prometheus::Family<prometheus::Counter>& http_requests_by_route_;
  /// Per gyro: rate, bias, temperature, gradient (gauges) and ticks without a counter answer.
  prometheus::Family<prometheus::Gauge>& slot_rate_;
  prometheus::Family<prometheus::Gauge>& slot_bias_;
  prometheus::Family<prometheus::Gauge>& slot_temp_;
  prometheus::Family<prometheus::Gauge>& slot_grad_;
  prometheus::Family<prometheus::Counter>& slot_latch_lost_;
  struct SlotLabels {
    std::map<std::string, std::string> labels;
    double earth_rate_dph = 0;
  };
  mutable std::mutex slots_mu_;
  std::map<std::string, SlotLabels> slots_;  ///< by serial
  prometheus::Gauge& stream_clients_;
  /// Registered by the first fleet(): runs and rows pending, last success.
  prometheus::Gauge* fleet_runs_ = nullptr;
  prometheus::Gauge* fleet_rows_ = nullptr;
  prometheus::Gauge* fleet_success_ = nullptr;
  prometheus::Counter* fleet_errors_ = nullptr;
  std::int64_t fleet_errors_seen_ = 0;
  std::vector<std::pair<std::string, prometheus::Gauge*>> fleet_states_;
  prometheus::Gauge* fleet_waiting_ = nullptr;
  std::mutex fleet_mu_;
};

}  // namespace station::live
