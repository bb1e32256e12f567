// The forwarder on its own thread (`serve` with [fleet]): passes while there is something to
// send, a pause of `interval_s` when there is not, and when the server is down a back-off of
// 0.5 s doubling to 60 s (issue 24) — the 1 Hz loop never waits on it: it shares nothing with
// the tick but the SQLite file (its own connections, WAL). Its state goes to a callback (the live
// hub and /metrics) after every pass.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stop_token>
#include <string>
#include <thread>

#include "station/fleet/forwarder.hpp"

namespace station::fleet {

struct ForwarderStatus {
  std::string state = "starting";  ///< sending, idle, backing off, refusing items (or holding)
  Backlog backlog;
  double last_success_unix_s = 0;  ///< wall time of the last pass that reached the server; 0: none
  std::string last_error;          ///< the last failure (link or refusal), empty when none yet
  double backoff_s = 0;            ///< current pause before the next attempt after a failure
  std::int64_t items_total = 0, rows_total = 0, errors_total = 0;
  nlohmann::json to_json() const;
};

class ForwarderThread {
 public:
  using OnStatus = std::function<void(const ForwarderStatus&)>;
  /// Starts the thread.
  ForwarderThread(std::string db_path, PgTarget target, ForwardOptions options, double interval_s,
                  OnStatus on_status);
  /// Stops it (a pass in flight ends first: bounded by the connection's timeouts).
  ~ForwarderThread();
  ForwarderThread(const ForwarderThread&) = delete;
  ForwarderThread& operator=(const ForwarderThread&) = delete;
  ForwarderStatus status() const;

 private:
  void loop(std::stop_token stop);
  void publish(ForwarderStatus s);
  bool pause(std::stop_token& stop, double seconds);

  Forwarder forwarder_;
  double interval_s_;
  OnStatus on_status_;
  mutable std::mutex mu_;
  std::condition_variable_any cv_;
  ForwarderStatus status_;
  std::jthread thread_;
};

}  // namespace station::fleet
