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
#include <span>
#include <string>
#include <string_view>
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

/// The metrics label of a request path: the documented path of the route it matches ("/api/runs/
/// {id}/stop"; "/static/*" for the page's files), or "other" (a scan cannot grow the series).
std::string route_label(const std::string& path);

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

  /// One endpoint: one row of the route table, one entry in schemas/api.md's endpoint table.
  struct Route {
    std::string_view method;   ///< GET | POST
    std::string_view path;     ///< as schemas/api.md writes it: /api/runs/{id}/bins
    std::string_view pattern;  ///< the regex httplib matches the request path against
    void (HttpServer::*handler)(const httplib::Request&, httplib::Response&);
  };
  /// Every endpoint, in the order httplib tries them (http_routes.cpp).
  static std::span<const Route> route_table();

 private:
  /// Limits, timeouts, headers, error bodies, the POST check, the request counter, the routes.
  void routes();
  /// Registers every row of route_table() with httplib.
  void register_routes();
  /// Before routing: a POST's token and body framing (answered and true when refused, and for a
  /// POST without Content-Length, dispatched here); false lets httplib go on.
  bool check_post(const httplib::Request& req, httplib::Response& res);
  /// Registers a POST route with httplib and in posts_, from where a POST without a body (no
  /// Content-Length, no Transfer-Encoding) is dispatched before httplib would wait for one.
  void post(const std::string& pattern, RouteHandler handler);
  /// Answers a POST without Content-Length as one with an empty body; false if no route matches.
  bool dispatch_bodyless_post(const httplib::Request& req, httplib::Response& res) const;
  // The handlers, one per row of route_table().
  void page(const httplib::Request& req, httplib::Response& res);
  void favicon(const httplib::Request& req, httplib::Response& res);
  void static_file(const httplib::Request& req, httplib::Response& res);
  void dygraphs_file(const httplib::Request& req, httplib::Response& res);
  void get_status(const httplib::Request& req, httplib::Response& res);
  void get_live(const httplib::Request& req, httplib::Response& res);
  void get_metrics(const httplib::Request& req, httplib::Response& res);
  void list_runs(const httplib::Request& req, httplib::Response& res);
  void get_run(const httplib::Request& req, httplib::Response& res);
  void get_bins(const httplib::Request& req, httplib::Response& res);
  void get_events(const httplib::Request& req, httplib::Response& res);
  void get_acceptance(const httplib::Request& req, httplib::Response& res);
  void get_report(const httplib::Request& req, httplib::Response& res);
  void event_stream(const httplib::Request& req, httplib::Response& res);
  void start_run(const httplib::Request& req, httplib::Response& res);
  void stop_run(const httplib::Request& req, httplib::Response& res);
  void abort_run(const httplib::Request& req, httplib::Response& res);
  void release_fit(const httplib::Request& req, httplib::Response& res);
  /// Ends the running run `{id}` (stop: bins and fits; abort: neither); 409/404 for another.
  void end_run(const httplib::Request& req, httplib::Response& res, bool abort);
  /// Runs `body` on the read-only store after the read check, one request at a time; a database
  /// that cannot be read is a 503 naming it.
  void db_read(const httplib::Request& req, httplib::Response& res,
               const std::function<void(Store&)>& body);
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
