// The API's read handlers (schemas/api.md): status, live, runs, bins, events, the event stream
// and the metrics. Each is one row of the route table (http_routes.cpp).
#include <fmt/format.h>

#include <algorithm>

#include "station/common/input_error.hpp"
#include "station/http/api_runs.hpp"
#include "station/http/http_server.hpp"
#include "station/http/json_reply.hpp"
#include "station/http/route_params.hpp"
#include "station/report/report_page.hpp"
#include "station/store/sqlite.hpp"

// Last: httplib.h (also through bounded_server.hpp) pulls in <resolv.h>, whose `_res` macro
// breaks Eigen headers included after it.
#include <httplib.h>

#include "station/http/bounded_server.hpp"

namespace station::http {

namespace {

/// 200 with the body of a known run, else 404 naming it.
void send_run_json(httplib::Response& res, std::int64_t run_id,
                   const std::optional<nlohmann::json>& j) {
  send_json(res, j ? 200 : 404,
            j ? *j : nlohmann::json{{"error", fmt::format("no run {}", run_id)}});
}

}  // namespace

void HttpServer::get_status(const httplib::Request& req, httplib::Response& res) {
  if (may_read(req, res)) send_json(res, 200, hub_.status());
}

void HttpServer::get_live(const httplib::Request& req, httplib::Response& res) {
  if (may_read(req, res)) send_json(res, 200, hub_.live());
}

void HttpServer::get_metrics(const httplib::Request& req, httplib::Response& res) {
  if (may_read(req, res)) res.set_content(hub_.metrics().text(), "text/plain; version=0.0.4");
}

// Database reads: one at a time on the read-only connection; a database that cannot be read
// (not created yet, locked for longer than the busy timeout) is a 503 naming it.
void HttpServer::db_read(const httplib::Request& req, httplib::Response& res,
                         const std::function<void(Store&)>& body) {
  if (!may_read(req, res)) return;
  std::lock_guard lock(store_mu_);  // held across the reset too: no other thread uses store_
  try {
    body(store());
  } catch (const SqliteError& e) {
    store_.reset();
    send_json(res, 503, {{"error", e.what()}});
  }
}

void HttpServer::list_runs(const httplib::Request& req, httplib::Response& res) {
  int limit = 100;
  if (req.has_param("limit")) {
    const auto v = positive_int(req.get_param_value("limit"));
    if (!v || *v > 10000) {
      send_json(res, 400, {{"error", "limit: expected an integer 1..10000"}});
      return;
    }
    limit = static_cast<int>(*v);
  }
  db_read(req, res, [&](Store& st) { send_json(res, 200, runs_json(st, limit)); });
}

void HttpServer::get_run(const httplib::Request& req, httplib::Response& res) {
  const auto id = path_id(req, res, "run id");
  if (!id) return;
  db_read(req, res, [&](Store& st) { send_run_json(res, *id, run_json(st, *id)); });
}

// A finished run's report, each page rendered from the store as `station report` writes it
// (report/report_page.hpp). The pages are self-contained with inline scripts and styles: their
// own policy allows those and nothing from anywhere (their data is JSON the script escapes).
void HttpServer::get_report(const httplib::Request& req, httplib::Response& res) {
  const std::string name = req.matches[1].str();
  db_read(req, res, [&](Store& st) {
    try {
      const auto page = report::report_page(st, name, options_.dygraphs_dir);
      if (!page) {
        send_json(res, 404,
                  {{"error", fmt::format("no report page '{}': run-ID.html or "
                                         "run-ID-slotN-SERIAL.html of a run in this database",
                                         name.substr(0, 120))}});
        return;
      }
      res.headers.erase("Content-Security-Policy");
      res.set_header("Content-Security-Policy",
                     "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
                     "img-src data:; frame-ancestors 'none'");
      res.set_content(*page, "text/html; charset=utf-8");
    } catch (const InputError& e) {  // e.g. libjs-dygraphs missing: the station's fault
      send_json(res, 500, {{"error", fmt::format("cannot render the report: {}", e.what())}});
    }
  });
}

void HttpServer::get_bins(const httplib::Request& req, httplib::Response& res) {
  const auto id = path_id(req, res, "run id");
  if (!id) return;
  // Live bins stand in only while the run runs: an aborted run stores none and shows none.
  const auto live = hub_.current_run() == id ? hub_.live_bins(*id) : std::nullopt;
  db_read(req, res, [&](Store& st) { send_run_json(res, *id, bins_json(st, *id, live)); });
}

void HttpServer::get_events(const httplib::Request& req, httplib::Response& res) {
  const auto id = path_id(req, res, "run id");
  if (!id) return;
  std::int64_t since = 0;
  if (req.has_param("since")) {
    const auto n = non_negative_int(req.get_param_value("since"));
    if (!n) {
      send_json(res, 400, {{"error", "since: expected an event id (integer >= 0)"}});
      return;
    }
    since = *n;
  }
  db_read(req, res, [&](Store& st) { send_run_json(res, *id, events_json(st, *id, since)); });
}

void HttpServer::event_stream(const httplib::Request& req, httplib::Response& res) {
  if (!may_read(req, res)) return;
  if (streams_.fetch_add(1) >= options_.max_streams) {
    streams_.fetch_sub(1);
    send_json(res, 503,
              {{"error", fmt::format("at most {} event streams at once", options_.max_streams)}});
    return;
  }
  // ?after=SEQ (the `seq` of /api/live): the stream starts right after it, so a page that read
  // the snapshot first misses nothing; without it, at the newest message.
  std::uint64_t start = hub_.last_id();
  if (req.has_param("after")) {
    const auto n = non_negative_int(req.get_param_value("after"));
    if (!n) {
      streams_.fetch_sub(1);
      send_json(res, 400, {{"error", "after: expected a stream id (integer >= 0)"}});
      return;
    }
    start = std::min<std::uint64_t>(static_cast<std::uint64_t>(*n), start);
  }
  hub_.metrics().stream_clients(streams_.load());
  exempt_from_response_deadline();  // endless by design; max_streams bounds how many
  auto after = std::make_shared<std::uint64_t>(start);
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, after](std::size_t, httplib::DataSink& sink) {
        std::vector<live::StreamMessage> msgs;
        if (!hub_.wait(*after, msgs, std::chrono::seconds(5))) {
          sink.done();  // shutting down: end the chunked stream properly
          return true;
        }
        if (msgs.empty()) {
          static constexpr std::string_view kAlive = ": keep-alive\n\n";
          return sink.write(kAlive.data(), kAlive.size());
        }
        std::string text;
        for (const auto& m : msgs) text += m.text;
        *after = msgs.back().id;
        return sink.write(text.data(), text.size());
      },
      [this](bool) { hub_.metrics().stream_clients(streams_.fetch_sub(1) - 1); });
}

// A run's acceptance figures as its end stored them (migration 12): none while it runs.
void HttpServer::get_acceptance(const httplib::Request& req, httplib::Response& res) {
  const auto id = path_id(req, res, "run id");
  if (!id) return;
  db_read(req, res,
          [&](Store& st) { send_run_json(res, *id, acceptance_results_json(st, *id)); });
}

}  // namespace station::http
