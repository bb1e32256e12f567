// cpp-httplib's server with the bounds it lacks (cpp-httplib 0.11 reads header lines without a
// count or total limit and times out each recv, not the request, on a fixed pool of workers):
// every connection gets its own thread up to a total, at most a few per client address, and
// one request, whose head must arrive whole within a deadline and pass request_rules.hpp
// before httplib parses it. Everything above the limits is answered at once (503, 408, 414,
// 431, 400) and closed. The routes, handlers and responses stay httplib's.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "station/http/request_rules.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include <httplib.h>

namespace station::http {

/// How much of the service one client may hold (schemas/api.md, "Limits").
struct ConnectionLimits {
  HeadLimits head;
  std::chrono::milliseconds request_deadline{10'000};  ///< the whole request (head and body)
  int max_connections = 64;                            ///< open at once, all clients
  int max_per_address = 32;                            ///< open at once from one address
};

class BoundedServer : public httplib::Server {
 public:
  /// `refused(status)` is called for every connection answered here (metrics).
  BoundedServer(ConnectionLimits limits, std::function<void(int)> refused);
  /// After a bind: listen(2) again with a backlog of `connections` (cpp-httplib 0.11 listens
  /// with 5, so a burst beyond it waits for SYN retransmits of 1 s and more before the caps
  /// above can even answer it).
  void set_backlog(int connections);

 private:
  bool process_and_close_socket(socket_t sock) override;
  /// Counts the connection against its address; false (and nothing counted) above the cap.
  bool admit(const std::string& address);
  void release(const std::string& address);
  /// Reads until the head is complete: its verdict, with the bytes read in `buffer`.
  HeadVerdict read_head(socket_t sock, std::chrono::steady_clock::time_point deadline,
                        std::string& buffer) const;
  void refuse(socket_t sock, const HeadVerdict& v) const;

  ConnectionLimits limits_;
  std::function<void(int)> refused_;
  std::mutex mu_;
  std::map<std::string, int> per_address_;
};

}  // namespace station::http
