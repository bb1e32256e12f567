#include "station/fleet/forwarder_thread.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "station/common/logging.hpp"

namespace station::fleet {

nlohmann::json ForwarderStatus::to_json() const {
  return {{"state", state},
          {"pending_runs", backlog.runs},
          {"pending_items", backlog.items},
          {"pending_rows", backlog.rows},
          {"held_items", backlog.held},
          {"last_success_unix_s",
           last_success_unix_s > 0 ? nlohmann::json(last_success_unix_s) : nlohmann::json()},
          {"last_error", last_error},
          {"backoff_s", backoff_s},
          {"waiting_s", waiting_s},
          {"waiting_for", waiting_for},
          {"items_total", items_total},
          {"rows_total", rows_total},
          {"errors_total", errors_total}};
}

ForwarderThread::ForwarderThread(std::string db_path, PgTarget target, ForwardOptions options,
                                 double interval_s, OnStatus on_status)
    : forwarder_(std::move(db_path), std::move(target), std::move(options)),
      interval_s_(interval_s),
      on_status_(std::move(on_status)),
      thread_([this](std::stop_token stop) { loop(stop); }) {}

// A pass in flight is cut short: the stop is checked between items and by every wait on the
// server (PgWatch), which cancels the call in flight, so a frozen server cannot hold the
// service's shutdown (systemd's TimeoutStopSec, station/package/gyro-station.service).
ForwarderThread::~ForwarderThread() {
  thread_.request_stop();
  cv_.notify_all();
}

ForwarderStatus ForwarderThread::status() const {
  std::lock_guard lock(mu_);
  return status_;
}

void ForwarderThread::publish(ForwarderStatus s) {
  {
    std::lock_guard lock(mu_);
    status_ = s;
  }
  try {
    if (on_status_) on_status_(s);
  } catch (const std::exception& e) {  // nothing may leave the thread (std::terminate)
    log("fleet")->error("status: {}", e.what());
  }
}

bool ForwarderThread::pause(std::stop_token& stop, double seconds) {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, stop, std::chrono::duration<double>(seconds), [] { return false; });
  return !stop.stop_requested();
}

// A call unanswered for kPgSlowCallS: said as it is, with the backlog counted again every 5 s
// (the run goes on adding to it; the count has its own SQLite connection).
void ForwarderThread::waiting(ForwarderStatus& s, double waited_s, std::string_view what) {
  if (s.state != "waiting on server" || waited_s - s.waiting_s >= 5) {
    try {
      s.backlog = forwarder_.backlog();
    } catch (const std::exception&) {  // the local file answers later
    }
  }
  s.state = "waiting on server";
  s.waiting_s = std::floor(waited_s);
  s.waiting_for = std::string(what.substr(0, std::min<std::size_t>(48, what.find('\n'))));
  publish(s);
}

void ForwarderThread::loop(std::stop_token stop) {
  ForwarderStatus s;
  std::string logged_error;
  forwarder_.set_watch(
      {[stop] { return stop.stop_requested(); },
       [this, &s](double waited_s, std::string_view what) { waiting(s, waited_s, what); }});
  auto backlog_at = std::chrono::steady_clock::time_point{};
  while (!stop.stop_requested()) {
    double wait_s = interval_s_;
    try {
      const PassResult p = forwarder_.pass(100, [&stop] { return stop.stop_requested(); });
      s.waiting_s = 0;
      s.waiting_for.clear();
      s.items_total += p.items;
      s.rows_total += p.rows;
      s.errors_total += p.failed;
      s.last_success_unix_s = unix_now_s();
      // The backlog at rest, and every 10 s of a catch-up (it counts what is pending).
      const auto now = std::chrono::steady_clock::now();
      if (!p.more || now - backlog_at > std::chrono::seconds(10)) {
        s.backlog = forwarder_.backlog();
        backlog_at = now;
      }
      if (p.failed > 0) s.last_error = p.last_error;
      s.backoff_s = 0;
      s.state = p.more ? "sending" : p.failed > 0 || s.backlog.held > 0 ? "refusing items" : "idle";
      wait_s = p.more ? 0 : interval_s_;
      if (p.failed > 0 && p.last_error != logged_error)
        log("fleet")->warn("the server refused {} item(s): {}", p.failed, p.last_error);
      logged_error = p.failed > 0 ? p.last_error : "";
    } catch (const std::exception& e) {
      forwarder_.disconnect();
      if (stop.stop_requested()) break;  // the call given up for the stop: nothing to report
      s.waiting_s = 0;
      s.waiting_for.clear();
      s.backoff_s = next_backoff_s(s.backoff_s);
      s.state = "backing off";
      s.last_error = e.what();
      ++s.errors_total;
      try {
        s.backlog = forwarder_.backlog();
      } catch (const std::exception&) {  // the local file answers later
      }
      if (s.last_error != logged_error)
        log("fleet")->warn("{} (retrying in {:.1f} s, doubling to 60 s)", s.last_error,
                           s.backoff_s);
      logged_error = s.last_error;
      wait_s = s.backoff_s;
    }
    publish(s);
    if (wait_s > 0 && !pause(stop, wait_s)) break;
  }
}

}  // namespace station::fleet
