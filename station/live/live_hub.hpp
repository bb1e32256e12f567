// What the station shows while it runs: the sequencer's thread tells the hub each tick, event
// and run start/end; HTTP threads read the status, the page's snapshot, the metrics, and wait on
// the event stream (schemas/api.md). No I/O here: the hub is memory with a lock and a condition
// variable, bounded (a trend of <= 2000 points, 512 stream messages, 50 events).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compensation/binning.hpp"
#include "station/config/protocol.hpp"
#include "station/daemon/idle_watch.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/live/live_bins.hpp"
#include "station/live/live_metrics.hpp"

namespace station::live {

/// What does not change while the daemon runs.
struct StationInfo {
  std::string station;
  bool sim = false;
  std::optional<double> speed;  ///< simulated seconds per wall second (--speed)
  double bin_s = compensation::kPaperBinS;
  /// The rig's slots for a start form: [{"slot", "node", "serial", "part"}], serial and part the
  /// configuration's defaults ("" for none; run_gyros.hpp). Empty: this daemon starts no runs.
  nlohmann::json rig_slots = nlohmann::json::array();
};

/// One event-stream message, formatted for the wire ("id: …\nevent: …\ndata: …\n\n").
struct StreamMessage {
  std::uint64_t id = 0;
  std::string text;
};

/// Chains the hub to a sequencer's hooks (keeping hooks already set): run start, ticks, events.
void attach(class LiveHub& hub, SequencerOptions& options);

/// The live state of one station. Thread-safe.
class LiveHub {
 public:
  explicit LiveHub(StationInfo info);

  void set_http_url(const std::string& url);
  /// A run starts (or resumes): its id, protocol, operator and slots; the live bins restart.
  void run_started(std::int64_t run_id, const Protocol& protocol, const std::string& operator_name,
                   const std::vector<RunSlot>& slots);
  void tick(const TickReport& r);
  void event(const RunEvent& e);
  /// The run ended in `state` (completed, stopped, aborted, …, or 'failed: why').
  void run_ended(std::int64_t run_id, const std::string& state);
  /// An idle look at the rig (serve between runs): devices as read, safety inputs, the fault.
  void idle(const IdleReading& r);

  /// The forwarder's state ([fleet]; station/fleet/forwarder_thread.hpp): in status() as
  /// "fleet" and on the page; null when the station forwards nowhere.
  void fleet(const nlohmann::json& forwarder);

  nlohmann::json status() const;
  /// status + trend + live bins + latest events + the last stream id they include.
  nlohmann::json live() const;
  /// Live bins of `run_id` if it is the hub's current (or last) run.
  std::optional<nlohmann::json> live_bins(std::int64_t run_id) const;
  std::optional<std::int64_t> current_run() const;  ///< the running run, if any
  LiveMetrics& metrics() { return metrics_; }

  /// Messages after `after_id` (blocks up to `timeout` when there are none). A reader that fell
  /// more than the buffer behind gets a 'resync' message first. Empty and false once closed.
  bool wait(std::uint64_t after_id, std::vector<StreamMessage>& out,
            std::chrono::milliseconds timeout);
  std::uint64_t last_id() const;
  /// Wakes and ends every waiting stream (shutdown).
  void close();

 private:
  void publish(const std::string& event, const nlohmann::json& data);  // lock held
  nlohmann::json status_locked() const;
  /// A sample as the page shows it: bias (rate − the slot's Earth rate), temperature, gradient.
  nlohmann::json slot_json(const SampleRow& s) const;
  /// The run-state metric, written only when the state or run changes (not every tick).
  void publish_state(std::int64_t run_id);
  std::string state_locked() const;

  const StationInfo info_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  bool closed_ = false;
  std::string http_url_;
  // The run
  std::optional<std::int64_t> run_id_, last_run_id_;
  Protocol protocol_;  ///< the run's (steps, targets, durations for the page)
  std::string operator_;
  std::map<std::string, double> earth_rate_dph_;  ///< per serial of the run
  std::optional<TickReport> last_;                ///< last tick (rows pointer cleared)
  std::vector<SampleRow> last_rows_;
  std::int64_t ticks_ = 0;
  std::string fault_;                ///< the idle rig's fault (serve), empty when clear
  std::string run_failure_;          ///< why the last run failed; kept until the next run starts
  std::optional<IdleReading> idle_;  ///< the last idle look (serve)
  nlohmann::json fleet_;             ///< the forwarder's state; null: no [fleet]
  // What the page draws
  std::vector<std::array<double, 3>> trend_;  ///< t_s, air_c, setpoint_c
  int trend_stride_ = 1;
  std::int64_t trend_seen_ = 0;
  std::optional<LiveBins> bins_;
  std::deque<nlohmann::json> events_;
  // The stream
  std::deque<StreamMessage> messages_;
  std::uint64_t next_id_ = 1;
  std::chrono::steady_clock::time_point last_tick_msg_{};
  LiveMetrics metrics_;
  std::string published_state_ = "idle";
  std::int64_t published_run_ = 0;
};

}  // namespace station::live
