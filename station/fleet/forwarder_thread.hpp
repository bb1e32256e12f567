// The forwarder on its own thread (`serve` with [fleet]): passes while there is something to
// send, a pause of `interval_s` when there is not, and when the server is down a back-off of
// 0.5 s doubling to 60 s (issue 24) — the 1 Hz loop never waits on it: it shares nothing with
// the tick but the SQLite file (its own connections, WAL). Its state goes to a callback (the live
// hub and /metrics) after every pass, and while a call waits on the server (issue 34 point 5):
// "waiting on server" with what it waits for, how long, and the backlog counted meanwhile. Every
// call is bounded (pg.hpp): a server that stops answering ends the pass in a timeout and a
// back-off as a lost one does, and a stop gives up the call in flight at once.
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
  /// starting, sending, idle, waiting on server, backing off, refusing items (or holding)
  std::string state = "starting";
  Backlog backlog;
  double waiting_s = 0;            ///< "waiting on server": how long the call in flight has waited
  std::string waiting_for;         ///< "waiting on server": the call (its first words)
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
  /// Stops it: a call in flight is given up at once (cancelled within kPgCancelTimeoutS).
  ~ForwarderThread();
  ForwarderThread(const ForwarderThread&) = delete;
  ForwarderThread& operator=(const ForwarderThread&) = delete;
  ForwarderStatus status() const;

 private:
  void loop(std::stop_token stop);
  void publish(ForwarderStatus s);
  void waiting(ForwarderStatus& s, double waited_s, std::string_view what);
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
