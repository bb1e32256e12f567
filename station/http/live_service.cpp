// Live service start-up: token file, bind, the address line.
#include "station/http/live_service.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "station/common/logging.hpp"
#include "station/http/token.hpp"

namespace station {

http::ControlReply OneRunControl::start(const std::string&, const std::string&,
                                        const std::vector<SlotGyro>&) {
  return {409,
          "this daemon is `station run`: it runs one protocol; start runs with `station serve`"};
}

http::ControlReply OneRunControl::stop(std::int64_t run_id, bool abort) {
  if (abort) abort_.store(true);
  stop_.store(true);
  return {202, fmt::format("run {} ends at the next tick ({})", run_id,
                           abort ? "aborted: no bins, no fit" : "stopped: binned and fitted")};
}

LiveService::LiveService(const LiveServiceOptions& o, http::RunControl& control) : hub_(o.info) {
  if (o.listen.empty()) return;
  http::HttpOptions ho = http::parse_listen(o.listen, "--http");
  ho.token = http::load_or_create_token(o.token_file.empty() ? o.db_path + ".token" : o.token_file);
  ho.db_path = o.db_path;
  server_ = std::make_unique<http::HttpServer>(ho, hub_, control);
  server_->start();
  // One line a script (or a test) can read for the chosen port.
  std::fputs(fmt::format("http: listening on {}\n", server_->url()).c_str(), stdout);
  std::fflush(stdout);
  log("http")->info("listening on {}", server_->url());
}

void LiveService::shutdown() {
  if (!server_) return;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the streams send the run's end
  if (server_->stop()) {
    server_.reset();
  } else {
    abandoned_ = true;
    (void)server_.release();  // its detached worker refers to it
  }
}

void LiveService::exit_if_abandoned(int rc) {
  if (!abandoned_) return;
  std::fflush(stdout);
  std::fflush(stderr);
  spdlog::shutdown();
  std::_Exit(rc);
}

}  // namespace station
