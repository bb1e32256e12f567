// The station's HTTP service (cpp-httplib, Debian libcpp-httplib-dev): the live page, the JSON
// API, the event stream and /metrics (schemas/api.md). Reads need no credentials from loopback;
// every POST, and every read from another host, needs the bearer token. No CORS headers; body,
// header and stream-count limits; the page is embedded in the binary, dygraphs read from the
// installed libjs-dygraphs by a fixed list of names. Runs on its own threads; a constructor does
// no I/O, start() binds.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "station/http/run_control.hpp"
#include "station/live/live_hub.hpp"
#include "station/store/store.hpp"

namespace httplib {
class Server;
struct Request;
struct Response;
}  // namespace httplib

namespace station::http {

/// Where and how to serve.
struct HttpOptions {
  std::string host = "127.0.0.1";
  int port = 8080;  ///< 0: any free port (start() returns it)
  std::string token;
  std::string db_path;  ///< the station database, opened read-only on first use
  std::string dygraphs_dir = "/usr/share/javascript/dygraphs";
  int max_streams = 4;
  std::size_t max_body_bytes = 64 * 1024;
};

/// Parses "HOST:PORT" (--http, [http] listen); throws InputError naming `what`.
HttpOptions parse_listen(const std::string& address, const std::string& what);

/// A route's handler, as httplib calls it.
using RouteHandler = std::function<void(const httplib::Request&, httplib::Response&)>;

class HttpServer {
 public:
  HttpServer(HttpOptions options, live::LiveHub& hub, RunControl& control);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// Binds and starts serving; returns the bound port. Throws InputError when it cannot bind.
  int start();
  /// Ends every stream and stops serving (idempotent). False when a client still held a worker
  /// after 3 s: the server is then left running detached, and the process must exit without
  /// destroying what it uses (LiveService::exit_if_abandoned).
  bool stop();
  /// "http://HOST:PORT/" once started.
  std::string url() const;

 private:
  void routes();
  void api_routes();
  void control_routes();
  /// Registers a POST route with httplib and in posts_, from where a POST without a body (no
  /// Content-Length, no Transfer-Encoding) is dispatched before httplib would wait for one.
  void post(const std::string& pattern, RouteHandler handler);
  /// Answers a POST without Content-Length as one with an empty body; false if no route matches.
  bool dispatch_bodyless_post(const httplib::Request& req, httplib::Response& res) const;
  /// POST /api/fits/{id}/release.
  void release_fit_route(const httplib::Request& req, httplib::Response& res);
  void stream_route();
  void static_routes();
  /// Whether the request may read (loopback, or the token); answers 401/403 when not.
  bool may_read(const httplib::Request& req, httplib::Response& res) const;
  bool may_write(const httplib::Request& req, httplib::Response& res) const;
  /// The read-only store (opened on first use; one request at a time).
  Store& store();

  HttpOptions options_;
  live::LiveHub& hub_;
  RunControl& control_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::atomic<int> streams_{0};
  std::atomic<bool> done_{false};  ///< the listen thread has returned
  std::mutex store_mu_;
  std::optional<Store> store_;
  struct PostRoute {
    std::regex pattern;
    RouteHandler handler;
  };
  std::vector<PostRoute> posts_;
};

}  // namespace station::http
