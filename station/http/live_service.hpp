// The live page, API and metrics of a daemon command (run --http, serve): a hub the sequencer
// feeds and the HTTP server that shows it. Prints the bound address as one stdout line.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>

#include "station/http/http_server.hpp"
#include "station/live/live_hub.hpp"

namespace station {

/// What the service needs to start.
struct LiveServiceOptions {
  std::string listen;      ///< HOST:PORT; empty: no HTTP (the hub still feeds nothing)
  std::string token_file;  ///< empty: DB.token
  std::string db_path;
  live::StationInfo info;
};

/// `run`'s control: one run per process. Stop and abort set the flags the sequencer watches.
class OneRunControl final : public http::RunControl {
 public:
  OneRunControl(std::atomic<bool>& stop, std::atomic<bool>& abort) : stop_(stop), abort_(abort) {}
  http::ControlReply start(const std::string&, const std::string&,
                           const std::vector<SlotGyro>&) override;
  http::ControlReply stop(std::int64_t run_id, bool abort) override;

 private:
  std::atomic<bool>& stop_;
  std::atomic<bool>& abort_;
};

/// The hub and, when `listen` is set, its HTTP server (started by the constructor: it binds).
class LiveService {
 public:
  LiveService(const LiveServiceOptions& options, http::RunControl& control);
  live::LiveHub& hub() { return hub_; }
  bool serving() const { return server_ != nullptr; }
  /// Where the page is served ("http://HOST:PORT/"); empty without HTTP.
  std::string url() const { return server_ ? server_->url() : std::string(); }
  /// Lets the event streams send what is queued (a run's end), then stops serving.
  void shutdown();
  /// After shutdown: if a client held the server past its 3 s, ends the process now with `rc`
  /// (stdout and logs flushed; committed data is safe, as after a kill) rather than destroy
  /// what the detached server still uses. Call it last in a command, with nothing unsaved.
  void exit_if_abandoned(int rc);

 private:
  live::LiveHub hub_;
  std::unique_ptr<http::HttpServer> server_;
  bool abandoned_ = false;
};

}  // namespace station
