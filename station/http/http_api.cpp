// The API's routes (schemas/api.md): status, runs, bins, events, control, the event stream and
// the metrics.
#include <fmt/format.h>

#include <algorithm>
#include <charconv>

#include "station/common/logging.hpp"
#include "station/http/api_runs.hpp"
#include "station/http/http_server.hpp"
#include "station/http/json_reply.hpp"
#include "station/release/releases.hpp"
#include "station/store/sqlite.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include <httplib.h>

namespace station::http {

namespace {

/// A positive decimal integer, or nullopt.
std::optional<std::int64_t> positive_int(const std::string& text) {
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || v <= 0)
    return std::nullopt;
  return v;
}

/// The run id of the path, or a 400 answered.
std::optional<std::int64_t> run_id_of(const httplib::Request& req, httplib::Response& res) {
  const auto id = positive_int(req.matches[1].str());
  if (!id)
    send_json(
        res, 400,
        {{"error", fmt::format("run id '{}': expected a positive integer", req.matches[1].str())}});
  return id;
}

/// A string field of a JSON object body: absent -> fallback (nullopt when required), else text.
std::optional<std::string> string_field(const nlohmann::json& body, const char* key,
                                        std::size_t max_len, std::string& error) {
  if (!body.contains(key)) return std::nullopt;
  if (!body[key].is_string() || body[key].get<std::string>().size() > max_len) {
    error = fmt::format("field '{}': expected a string of at most {} characters", key, max_len);
    return std::nullopt;
  }
  return body[key].get<std::string>();
}

}  // namespace

void HttpServer::api_routes() {
  auto& s = *server_;
  s.Get("/api/status", [this](const httplib::Request& req, httplib::Response& res) {
    if (may_read(req, res)) send_json(res, 200, hub_.status());
  });
  s.Get("/api/live", [this](const httplib::Request& req, httplib::Response& res) {
    if (may_read(req, res)) send_json(res, 200, hub_.live());
  });
  s.Get("/metrics", [this](const httplib::Request& req, httplib::Response& res) {
    if (may_read(req, res)) res.set_content(hub_.metrics().text(), "text/plain; version=0.0.4");
  });
  // Database reads: one at a time on the read-only connection; a database that cannot be read
  // (not created yet, locked for longer than the busy timeout) is a 503 naming it.
  const auto db_read = [this](const httplib::Request& req, httplib::Response& res, auto&& body) {
    if (!may_read(req, res)) return;
    std::lock_guard lock(store_mu_);  // held across the reset too: no other thread uses store_
    try {
      body(store());
    } catch (const SqliteError& e) {
      store_.reset();
      send_json(res, 503, {{"error", e.what()}});
    }
  };
  s.Get("/api/runs", [db_read](const httplib::Request& req, httplib::Response& res) {
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
  });
  s.Get(R"(/api/runs/([^/]+))", [db_read](const httplib::Request& req, httplib::Response& res) {
    const auto id = run_id_of(req, res);
    if (!id) return;
    db_read(req, res, [&](Store& st) {
      const auto j = run_json(st, *id);
      send_json(res, j ? 200 : 404,
                j ? *j : nlohmann::json{{"error", fmt::format("no run {}", *id)}});
    });
  });
  s.Get(R"(/api/runs/([^/]+)/bins)",
        [this, db_read](const httplib::Request& req, httplib::Response& res) {
          const auto id = run_id_of(req, res);
          if (!id) return;
          // Live bins stand in only while the run runs: an aborted run stores none and shows none.
          const auto live = hub_.current_run() == id ? hub_.live_bins(*id) : std::nullopt;
          db_read(req, res, [&](Store& st) {
            const auto j = bins_json(st, *id, live);
            send_json(res, j ? 200 : 404,
                      j ? *j : nlohmann::json{{"error", fmt::format("no run {}", *id)}});
          });
        });
  s.Get(R"(/api/runs/([^/]+)/events)",
        [db_read](const httplib::Request& req, httplib::Response& res) {
          const auto id = run_id_of(req, res);
          if (!id) return;
          std::int64_t since = 0;
          if (req.has_param("since")) {
            const std::string v = req.get_param_value("since");
            const auto n = v == "0" ? std::optional<std::int64_t>(0) : positive_int(v);
            if (!n) {
              send_json(res, 400, {{"error", "since: expected an event id (integer >= 0)"}});
              return;
            }
            since = *n;
          }
          db_read(req, res, [&](Store& st) {
            const auto j = events_json(st, *id, since);
            send_json(res, j ? 200 : 404,
                      j ? *j : nlohmann::json{{"error", fmt::format("no run {}", *id)}});
          });
        });
}

void HttpServer::post(const std::string& pattern, RouteHandler handler) {
  server_->Post(pattern, handler);
  posts_.push_back({std::regex(pattern), std::move(handler)});
}

// cpp-httplib 0.11 reads a POST without Content-Length until the connection closes and then
// answers 400 (its issues #523, #1738): the route is called here instead, with the empty body
// RFC 9112 6.3 gives such a request.
bool HttpServer::dispatch_bodyless_post(const httplib::Request& req, httplib::Response& res) const {
  for (const auto& route : posts_) {
    httplib::Request copy = req;
    if (!std::regex_match(copy.path, copy.matches, route.pattern)) continue;
    copy.body.clear();
    route.handler(copy, res);
    return true;
  }
  return false;
}

void HttpServer::control_routes() {
  post("/api/runs", [this](const httplib::Request& req, httplib::Response& res) {
    if (!may_write(req, res)) return;
    const auto body = nlohmann::json::parse(req.body, nullptr, false);
    if (body.is_discarded() || !body.is_object()) {
      send_json(res, 400,
                {{"error",
                  "body: expected a JSON object {\"protocol\": NAME, "
                  "\"operator\": NAME}"}});
      return;
    }
    std::string error;
    const auto protocol = string_field(body, "protocol", 4096, error);
    const auto op = string_field(body, "operator", 200, error);
    if (!error.empty() || !protocol || protocol->empty()) {
      send_json(res, 400, {{"error", error.empty() ? "field 'protocol' is required" : error}});
      return;
    }
    const ControlReply r = control_.start(*protocol, op.value_or(""));
    nlohmann::json reply = r.status < 300 ? nlohmann::json{{"accepted", r.message}}
                                          : nlohmann::json{{"error", r.message}};
    if (r.run_id > 0) reply["run_id"] = r.run_id;
    send_json(res, r.status, reply);
  });
  const auto end_run = [this](bool abort) {
    return [this, abort](const httplib::Request& req, httplib::Response& res) {
      if (!may_write(req, res)) return;
      const auto id = run_id_of(req, res);
      if (!id) return;
      const auto current = hub_.current_run();
      if (current != id) {
        bool exists = false;
        {
          std::lock_guard lock(store_mu_);
          try {
            exists = run_json(store(), *id).has_value();
          } catch (const SqliteError&) {
            store_.reset();
          }
        }
        send_json(res, exists ? 409 : 404,
                  {{"error", exists ? fmt::format("run {} is not running", *id)
                                    : fmt::format("no run {}", *id)}});
        return;
      }
      const ControlReply r = control_.stop(*id, abort);
      log("http")->info("run {} {} requested from {}", *id, abort ? "abort" : "stop",
                        req.remote_addr);
      send_json(res, r.status,
                r.status < 300 ? nlohmann::json{{"accepted", r.message}}
                               : nlohmann::json{{"error", r.message}});
    };
  };
  post(R"(/api/runs/([^/]+)/stop)", end_run(false));
  post(R"(/api/runs/([^/]+)/abort)", end_run(true));
  post(R"(/api/fits/([^/]+)/release)", [this](const httplib::Request& req, httplib::Response& res) {
    release_fit_route(req, res);
  });
}

// POST /api/fits/{id}/release {"by", "note", "override"}: the same rules as `station release`,
// on a short-lived writing connection (the API's own connection is read-only).
void HttpServer::release_fit_route(const httplib::Request& req, httplib::Response& res) {
  if (!may_write(req, res)) return;
  const auto id = positive_int(req.matches[1].str());
  if (!id) {
    send_json(
        res, 400,
        {{"error", fmt::format("fit id '{}': expected a positive integer", req.matches[1].str())}});
    return;
  }
  const auto body = nlohmann::json::parse(req.body, nullptr, false);
  std::string error;
  std::optional<std::string> by, note, override_reason;
  if (body.is_discarded() || !body.is_object()) {
    error = "body: expected a JSON object {\"by\": NAME, \"note\": TEXT, \"override\": REASON}";
  } else {
    by = string_field(body, "by", 200, error);
    note = string_field(body, "note", 4096, error);
    override_reason = string_field(body, "override", 4096, error);
    if (error.empty() && (!by || by->empty())) error = "field 'by' is required";
  }
  if (!error.empty()) {
    send_json(res, 400, {{"error", error}});
    return;
  }
  try {
    Store store(options_.db_path, OpenMode::existing);
    const ReleaseRow r = release_fit(store, {*id, *by, note.value_or(""), override_reason});
    log("http")->info("fit {} of {} released by {} from {}", r.fit_id, r.serial, r.released_by,
                      req.remote_addr);
    send_json(res, 201, release_json(r));
  } catch (const FitNotFound& e) {
    send_json(res, 404, {{"error", e.what()}});
  } catch (const ReleaseRefused& e) {
    send_json(res, 409, {{"error", e.what()}});
  } catch (const InputError& e) {
    send_json(res, 400, {{"error", e.what()}});
  } catch (const SqliteError& e) {
    send_json(res, 503, {{"error", e.what()}});
  }
}

void HttpServer::stream_route() {
  server_->Get("/api/events/stream", [this](const httplib::Request& req, httplib::Response& res) {
    if (!may_read(req, res)) return;
    if (streams_.fetch_add(1) >= options_.max_streams) {
      streams_.fetch_sub(1);
      send_json(res, 503,
                {{"error", fmt::format("at most {} event streams at once", options_.max_streams)}});
      return;
    }
    // ?after=SEQ (the `seq` of /api/live): the stream starts right after it, so a page that
    // read the snapshot first misses nothing; without it, at the newest message.
    std::uint64_t start = hub_.last_id();
    if (req.has_param("after")) {
      const std::string v = req.get_param_value("after");
      const auto n = v == "0" ? std::optional<std::int64_t>(0) : positive_int(v);
      if (!n) {
        streams_.fetch_sub(1);
        send_json(res, 400, {{"error", "after: expected a stream id (integer >= 0)"}});
        return;
      }
      start = std::min<std::uint64_t>(static_cast<std::uint64_t>(*n), start);
    }
    hub_.metrics().stream_clients(streams_.load());
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
  });
}

}  // namespace station::http
