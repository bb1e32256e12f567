// The API's control handlers (schemas/api.md): start a run, stop or abort the running one,
// release a fit. Every POST needs the token; each is one row of the route table.
#include <fmt/format.h>

#include "station/common/input_error.hpp"
#include "station/common/logging.hpp"
#include "station/common/text_rule.hpp"
#include "station/http/api_runs.hpp"
#include "station/http/api_slots.hpp"
#include "station/http/http_server.hpp"
#include "station/http/json_reply.hpp"
#include "station/http/route_params.hpp"
#include "station/release/releases.hpp"
#include "station/store/sqlite.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include <httplib.h>

namespace station::http {

namespace {

/// A control reply as the API answers it: {"accepted": …} below 300, else {"error": …}.
nlohmann::json control_json(const ControlReply& r) {
  return r.status < 300 ? nlohmann::json{{"accepted", r.message}}
                        : nlohmann::json{{"error", r.message}};
}

}  // namespace

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

// POST /api/runs {"protocol", "operator", "slots"}.
void HttpServer::start_run(const httplib::Request& req, httplib::Response& res) {
  if (!may_write(req, res)) return;
  const auto body = nlohmann::json::parse(req.body, nullptr, false);
  if (body.is_discarded() || !body.is_object()) {
    send_json(res, 400,
              {{"error", "body: expected a JSON object {\"protocol\": NAME, \"operator\": NAME}"}});
    return;
  }
  std::string error;
  if (!known_keys_only(body, {"protocol", "operator", "slots"}, error)) {
    send_json(res, 400, {{"error", error}});
    return;
  }
  const auto protocol = string_field(body, "protocol", 4096, error);
  const auto op = string_field(body, "operator", kMaxPersonBytes, error);
  const auto gyros = error.empty() ? slots_field(body, error) : std::vector<SlotGyro>{};
  if (!error.empty() || !protocol || protocol->empty()) {
    send_json(res, 400, {{"error", error.empty() ? "field 'protocol' is required" : error}});
    return;
  }
  const ControlReply r = control_.start(*protocol, op.value_or(""), gyros);
  nlohmann::json reply = control_json(r);
  if (r.run_id > 0) reply["run_id"] = r.run_id;
  send_json(res, r.status, reply);
}

void HttpServer::stop_run(const httplib::Request& req, httplib::Response& res) {
  end_run(req, res, false);
}

void HttpServer::abort_run(const httplib::Request& req, httplib::Response& res) {
  end_run(req, res, true);
}

// Only the running run can end: another known one is 409, an unknown one 404.
void HttpServer::end_run(const httplib::Request& req, httplib::Response& res, bool abort) {
  if (!may_write(req, res)) return;
  const auto id = path_id(req, res, "run id");
  if (!id) return;
  // No fields: an empty body or {} (a key it does not know is refused, as for every POST).
  const auto body =
      req.body.empty() ? nlohmann::json::object() : nlohmann::json::parse(req.body, nullptr, false);
  std::string error;
  if (body.is_discarded() || !body.is_object() || !known_keys_only(body, {}, error)) {
    send_json(res, 400, {{"error", error.empty() ? "body: expected nothing, or {}" : error}});
    return;
  }
  if (hub_.current_run() != id) {
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
  log("http")->info("run {} {} requested from {}", *id, abort ? "abort" : "stop", req.remote_addr);
  send_json(res, r.status, control_json(r));
}

// POST /api/fits/{id}/release {"by", "note", "override"}: the same rules as `station release`,
// on a short-lived writing connection (the API's own connection is read-only).
void HttpServer::release_fit(const httplib::Request& req, httplib::Response& res) {
  if (!may_write(req, res)) return;
  const auto id = path_id(req, res, "fit id");
  if (!id) return;
  const auto body = nlohmann::json::parse(req.body, nullptr, false);
  std::string error;
  std::optional<std::string> by, note, override_reason;
  if (body.is_discarded() || !body.is_object()) {
    error = "body: expected a JSON object {\"by\": NAME, \"note\": TEXT, \"override\": REASON}";
  } else if (known_keys_only(body, {"by", "note", "override"}, error)) {
    by = string_field(body, "by", kMaxPersonBytes, error);
    note = string_field(body, "note", kMaxNoteBytes, error);
    override_reason = string_field(body, "override", kMaxNoteBytes, error);
    if (error.empty() && (!by || by->empty())) error = "field 'by' is required";
  }
  if (!error.empty()) {
    send_json(res, 400, {{"error", error}});
    return;
  }
  try {
    Store store(options_.db_path, OpenMode::existing);
    const ReleaseRow r =
        station::release_fit(store, {*id, *by, note.value_or(""), override_reason});
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

}  // namespace station::http
