// Server set-up: limits, timeouts, error bodies, the request counter, the page and the stream.
#include "station/http/http_server.hpp"

#include <fmt/format.h>
#include <sys/socket.h>

#include <charconv>
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "station/common/input_error.hpp"
#include "station/common/logging.hpp"
#include "station/http/json_reply.hpp"
#include "station/http/request_rules.hpp"
#include "station/http/token.hpp"
#include "station/web/builtin_web.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include "station/http/bounded_server.hpp"

namespace station::http {

namespace {

/// One rule for what loopback is: the per-client cap's (bounded_server.hpp).
bool is_loopback(const std::string& addr) {
  return client_of(addr) == "loopback";
}

const char* mime_of(std::string_view name) {
  if (name.ends_with(".html")) return "text/html; charset=utf-8";
  if (name.ends_with(".js")) return "text/javascript; charset=utf-8";
  if (name.ends_with(".css")) return "text/css; charset=utf-8";
  if (name.ends_with(".png")) return "image/png";
  return "application/octet-stream";
}

/// A handler threw: 500 with what it said, logged.
void answer_exception(const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
  std::string what = "unknown error";
  try {
    if (ep) std::rethrow_exception(ep);
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
  }
  log("http")->warn("{} {}: {}", req.method, req.path, what);
  send_json(res, 500, {{"error", what}});
}

/// httplib's own errors (no route, body too large, malformed) as the API's JSON error body.
void answer_error(const httplib::Request& req, httplib::Response& res) {
  if (!res.body.empty()) return;
  std::string what = fmt::format("HTTP {}", res.status);
  if (res.status == 413) what = "request body too large (limit 64 KiB)";
  if (res.status == 404) what = fmt::format("no such resource: {}", req.path);
  if (res.status == 400 && what.starts_with("HTTP")) what = "malformed request";
  send_json(res, res.status, {{"error", what}});
}

}  // namespace

void send_json(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_content(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                  "application/json");
}

HttpOptions parse_listen(const std::string& address, const std::string& what) {
  const auto colon = address.rfind(':');
  HttpOptions o;
  if (colon == std::string::npos || colon == 0)
    throw InputError(
        fmt::format("{} '{}': expected HOST:PORT, e.g. 127.0.0.1:8080", what, address));
  o.host = address.substr(0, colon);
  if (o.host.size() > 2 && o.host.front() == '[' && o.host.back() == ']')
    o.host = o.host.substr(1, o.host.size() - 2);
  if (o.host == "localhost") o.host = "127.0.0.1";
  const std::string port = address.substr(colon + 1);
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), o.port);
  if (port.empty() || ec != std::errc() || end != port.data() + port.size() || o.port < 0 ||
      o.port > 65535)
    throw InputError(fmt::format("{} '{}': port must be 0..65535", what, address));
  return o;
}

HttpServer::HttpServer(HttpOptions options, live::LiveHub& hub, RunControl& control)
    : options_(std::move(options)), hub_(hub), control_(control) {}

HttpServer::~HttpServer() {
  stop();
}

Store& HttpServer::store() {
  if (!store_) store_.emplace(options_.db_path, OpenMode::read_only);
  return *store_;
}

bool HttpServer::may_read(const httplib::Request& req, httplib::Response& res) const {
  // Token-free only from loopback and addressed to a loopback name.
  if (is_loopback(req.remote_addr) && loopback_host(req.get_header_value("Host"))) return true;
  return may_write(req, res);
}

bool HttpServer::may_write(const httplib::Request& req, httplib::Response& res) const {
  if (!req.has_header("Authorization")) {
    res.set_header("WWW-Authenticate", "Bearer");
    send_json(res, 401,
              {{"error",
                "this request needs 'Authorization: Bearer TOKEN' (the "
                "token file's line)"}});
    return false;
  }
  if (!bearer_matches(req.get_header_value("Authorization"), options_.token)) {
    send_json(res, 403, {{"error", "token refused"}});
    return false;
  }
  return true;
}

void HttpServer::page(const httplib::Request&, httplib::Response& res) {
  for (const auto& [name, text] : builtin::kWebFiles)
    if (name == "index.html") res.set_content(std::string(text), mime_of(name));
}

void HttpServer::favicon(const httplib::Request&, httplib::Response& res) {
  res.status = 204;
}

// Only the embedded files: nothing on disk is reachable by name, so no path can traverse.
void HttpServer::static_file(const httplib::Request& req, httplib::Response& res) {
  for (const auto& [name, text] : builtin::kWebFiles) {
    if (name == req.matches[1].str()) {
      res.set_content(std::string(text), mime_of(name));
      return;
    }
  }
  send_json(res, 404, {{"error", fmt::format("no static file '{}'", req.matches[1].str())}});
}

void HttpServer::dygraphs_file(const httplib::Request& req, httplib::Response& res) {
  const std::string path = options_.dygraphs_dir + "/" + req.matches[1].str();
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    send_json(res, 404, {{"error", fmt::format("{}: not installed (libjs-dygraphs)", path)}});
    return;
  }
  std::ostringstream text;
  text << in.rdbuf();
  res.set_content(text.str(), mime_of(path));
}

// Before any body is read (httplib checks its size limit only for Content-Length bodies and
// inflates gzip without one): a POST must carry the token and a plain Content-Length within
// the limit, no Transfer-Encoding, no Content-Encoding. Refused requests close the connection.
bool HttpServer::check_post(const httplib::Request& req, httplib::Response& res) {
  if (req.method == "GET" || req.method == "HEAD") return false;
  const auto refuse = [&res](int status, const std::string& what) {
    res.set_header("Connection", "close");
    send_json(res, status, {{"error", what}});
    return true;
  };
  if (req.method != "POST")
    return refuse(405, fmt::format("method {} not allowed", req.method.substr(0, 16)));
  if (!may_write(req, res)) {
    res.set_header("Connection", "close");
    return true;
  }
  if (req.has_header("Transfer-Encoding"))
    return refuse(411, "a POST needs a Content-Length (no Transfer-Encoding)");
  if (req.has_header("Content-Encoding"))
    return refuse(415, "a POST body must not be encoded (no Content-Encoding)");
  // No Content-Length and no Transfer-Encoding: the body has length 0 (RFC 9112 6.3, item 7),
  // as `curl -X POST URL` sends it.
  const std::string length = req.get_header_value("Content-Length");
  std::size_t n = 0;
  const auto [end, ec] = std::from_chars(length.data(), length.data() + length.size(), n);
  if (!length.empty() && (ec != std::errc() || end != length.data() + length.size()))
    return refuse(400, "Content-Length is not a number (RFC 9112 6.3)");
  if (length.empty()) {
    res.set_header("Connection", "close");
    if (!dispatch_bodyless_post(req, res))
      send_json(res, 404, {{"error", fmt::format("no such resource: {}", req.path)}});
    return true;
  }
  if (n > options_.max_body_bytes) return refuse(413, "request body too large (limit 64 KiB)");
  return false;
}

void HttpServer::routes() {
  auto& s = *server_;
  s.set_payload_max_length(options_.max_body_bytes);
  s.set_tcp_nodelay(true);
  // httplib's default socket options add SO_REUSEPORT: a second daemon would then listen on the
  // same port beside the first and the kernel would split requests between them. Only
  // SO_REUSEADDR (a restart may bind while old connections sit in TIME_WAIT).
  s.set_socket_options([](int sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });  // small JSON answers: Nagle + delayed ACK cost 40 ms each
  s.set_read_timeout(5);
  s.set_write_timeout(5);
  s.set_keep_alive_timeout(5);
  s.set_default_headers({{"X-Content-Type-Options", "nosniff"},
                         {"Cache-Control", "no-store"},
                         {"Content-Security-Policy",
                          "default-src 'self'; style-src 'self' 'unsafe-inline'; "
                          "frame-ancestors 'none'"}});
  s.set_exception_handler(answer_exception);
  s.set_error_handler(answer_error);
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    return check_post(req, res) ? httplib::Server::HandlerResponse::Handled
                                : httplib::Server::HandlerResponse::Unhandled;
  });
  s.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    hub_.metrics().http_request(res.status, route_label(req.path));
  });
  register_routes();
}

int HttpServer::start() {
  // A thread per connection, bounded in number, per address and in time (bounded_server.hpp):
  // the event streams and slow clients hold only their own.
  const ConnectionLimits limits;
  auto bounded = std::make_unique<BoundedServer>(
      limits, [this](int status) { hub_.metrics().http_request(status); },
      [token = options_.token](std::string_view authorization) {
        return !token.empty() && bearer_matches(authorization, token);
      });
  BoundedServer& server = *bounded;
  server_ = std::move(bounded);
  routes();
  if (options_.port == 0) {
    port_ = server_->bind_to_any_port(options_.host);
  } else {
    port_ = server_->bind_to_port(options_.host, options_.port) ? options_.port : -1;
  }
  if (port_ <= 0)
    throw InputError(
        fmt::format("--http {}:{}: cannot listen there (address in use or not this "
                    "machine's)",
                    options_.host, options_.port));
  server.set_backlog(limits.max_connections);
  thread_ = std::thread([this, server = server_.get()] {
    server->listen_after_bind();
    done_.store(true);
  });
  hub_.set_http_url(url());
  return port_;
}

bool HttpServer::stop() {
  if (!server_) return true;
  if (!thread_.joinable()) {  // bound but never served (start() failed): nothing runs
    server_.reset();
    return true;
  }
  hub_.close();  // ends the streams' waits
  server_->stop();
  // Head reads end within 100 ms of the stop and every request within its deadline; should a
  // worker still run after 3 s (a handler blocked writing), leave the server to the process's
  // exit rather than hang a daemon's shutdown (systemd would SIGKILL it).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (!done_.load() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (!done_.load()) {
    log("http")->warn("a client still holds a connection: leaving it to the process's exit");
    thread_.detach();
    (void)server_.release();  // its worker may still run: never destroyed
    return false;
  }
  if (thread_.joinable()) thread_.join();
  server_.reset();
  return true;
}

std::string HttpServer::url() const {
  const bool v6 = options_.host.find(':') != std::string::npos;
  return v6 ? fmt::format("http://[{}]:{}/", options_.host, port_)
            : fmt::format("http://{}:{}/", options_.host, port_);
}

}  // namespace station::http
