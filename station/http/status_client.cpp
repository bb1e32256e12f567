// GET /api/status from a running station (status_client.hpp).
#include "station/http/status_client.hpp"

#include <fmt/format.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <future>
#include <optional>

#include "station/common/input_error.hpp"
#include "station/http/http_server.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro would reach the headers above.
#include <httplib.h>

namespace station::http {

std::pair<std::string, int> reach_address(const std::string& listen) {
  // The listen address read by the server's own rule (http_server.hpp parse_listen).
  const HttpOptions o = parse_listen(listen, "--http");
  if (o.port == 0)
    throw InputError(fmt::format(
        "--http '{}': port 0 is the one the station picked at its start (it printed it): give "
        "probe --http HOST:PORT",
        listen));
  std::string host = o.host;
  if (host.empty() || host == "0.0.0.0") host = "127.0.0.1";
  if (host == "::") host = "::1";
  return {host, o.port};
}

namespace {

/// A status answer is a few kilobytes (schemas/api.md); more is not a station's.
constexpr std::size_t kMaxStatusBytes = 1 << 20;

using Clock = std::chrono::steady_clock;

struct Exchange {
  std::optional<httplib::Result> res;  ///< set once the exchange ended
  std::string body;
  bool too_big = false, late = false;
};

// GET /api/status on its own thread under one deadline for the whole exchange (httplib's
// timeouts bound each read, not the answer): at the deadline the socket is shut (Client::stop).
// The body is capped at kMaxStatusBytes.
Exchange get_within(httplib::Client& client, Clock::time_point deadline) {
  Exchange x;
  auto task = std::async(std::launch::async, [&] {
    return client.Get("/api/status", [&](const char* data, std::size_t n) {
      x.too_big = x.body.size() + n > kMaxStatusBytes;
      if (!x.too_big) x.body.append(data, n);
      return !x.too_big && Clock::now() < deadline;
    });
  });
  if (task.wait_until(deadline) != std::future_status::ready) {
    x.late = true;
    do client.stop();
    while (task.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready);
  }
  x.res.emplace(task.get());
  x.late = x.late || (!*x.res && Clock::now() >= deadline);
  return x;
}

}  // namespace

StatusAnswer fetch_status(const std::string& listen, double timeout_s) {
  const auto [host, port] = reach_address(listen);
  StatusAnswer a;
  const std::string shown = host.find(':') == std::string::npos ? host : "[" + host + "]";
  a.url = fmt::format("http://{}:{}/api/status", shown, port);
  httplib::Client client(host, port);
  const auto whole_s = static_cast<time_t>(timeout_s);
  const auto rest_us = static_cast<time_t>(std::lround((timeout_s - whole_s) * 1e6));
  client.set_connection_timeout(whole_s, rest_us);
  client.set_read_timeout(whole_s, rest_us);
  const auto x = get_within(client, Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                       std::chrono::duration<double>(timeout_s)));
  if (x.too_big)
    a.error = fmt::format("an answer over {} bytes: not a station's status", kMaxStatusBytes);
  else if (x.late)
    a.error = fmt::format("no whole answer within {:g} s", timeout_s);
  else if (!*x.res)
    a.error = httplib::to_string(x.res->error());
  else if ((*x.res)->status != 200)
    a.error = fmt::format("HTTP {}: {}", (*x.res)->status, x.body.substr(0, 200));
  if (!a.error.empty()) return a;
  try {
    a.status = nlohmann::json::parse(x.body);
  } catch (const nlohmann::json::exception& e) {
    a.error = fmt::format("not JSON: {}", e.what());
    return a;
  }
  if (!a.status->is_object()) {
    a.error = "not a station's status: the answer is not a JSON object";
    a.status.reset();
  }
  return a;
}

}  // namespace station::http
