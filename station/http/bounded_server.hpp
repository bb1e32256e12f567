// cpp-httplib's server with the bounds it lacks (cpp-httplib 0.11 reads header lines without a
// count or total limit and times out each recv, not the request, on a fixed pool of workers):
// every connection gets its own thread up to a total, at most a few per client, and one request,
// whose head must arrive whole within a deadline and pass request_rules.hpp before httplib parses
// it. A connection beyond a cap takes the place of the oldest one still waiting for its head (a
// slow client; of the same client when its cap is the one reached, else of the client holding
// the most), or is answered 503 at once when every slot is serving a request. Once its head is
// read, a request without the API token is served only while the token holder's share is free.
// Everything above the limits is answered at once (503, 408, 414, 431, 400) and closed. A
// response has a deadline of its own, scaled to what it sends (a reader slower than
// DeadlineStream's minimum throughput is cut off), and threads are capped before a connection
// gets one (kThreadsPerPlace). The routes, handlers and responses stay httplib's.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "station/http/request_rules.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include <httplib.h>

namespace station::http {

/// How much of the service one client may hold (schemas/api.md, "Limits").
struct ConnectionLimits {
  HeadLimits head;
  std::chrono::milliseconds request_deadline{10'000};  ///< the whole request (head and body)
  int max_connections = 64;                            ///< open at once, all clients
  int max_per_client = 32;  ///< open at once from one client (client_of: all loopback is one)
  /// Of `max_connections`, and of each client's `max_per_client`, the slots a request without
  /// the API token may not take: kept for the token holder.
  int token_reserve = 8;
};

/// The client a peer address counts as for the per-client cap: every loopback address
/// (127.0.0.0/8, ::1, ::ffff:127.x.y.z) is the one client "loopback" (this machine's users can
/// bind any of them), any other address itself (an IPv4-mapped one as its IPv4 form).
std::string client_of(std::string_view address);

/// Called by a handler whose response has no end (the event stream, capped by its handler): its
/// writes each have a few seconds instead of the response deadline a response otherwise has
/// (DeadlineStream, bounded_server.cpp).
void exempt_from_response_deadline();

class BoundedServer : public httplib::Server {
 public:
  /// How long a new connection's head is read before it is counted: a client sends its head
  /// with its connection (the bytes follow the handshake's last ACK), so a request that came
  /// whole is judged at once and can never lose its place to a newer connection; a head not
  /// whole by then is read on as a counted connection, whose place a newer one may take.
  static constexpr std::chrono::milliseconds kFirstBytes{50};
  /// Threads at most per place of `max_connections`: a connection's thread lives on after its
  /// place is given up (a shed one answering 503, a refused one, one reading its first
  /// kFirstBytes), so each place may have one such beside its current holder. Beyond, a new
  /// connection is answered 503 on the accept thread without a wait and closed: the thread
  /// count does not grow with the connection rate.
  static constexpr int kThreadsPerPlace = 2;

  /// `refused(status)` is called for every connection answered here (metrics);
  /// `token_holder(authorization)` says whether an Authorization header value carries the API
  /// token (the token's share of the slots).
  BoundedServer(ConnectionLimits limits, std::function<void(int)> refused,
                std::function<bool(std::string_view)> token_holder);
  /// After a bind: listen(2) again with a backlog of `connections` (cpp-httplib 0.11 listens
  /// with 5, so a burst beyond it waits for SYN retransmits of 1 s and more before the caps
  /// above can even answer it).
  void set_backlog(int connections);
  /// The connections counted against the caps now (a shed one no longer is).
  int open_connections();

 private:
  /// One admitted connection, from its admission to the end of its thread.
  struct Slot {
    Slot(socket_t s, std::string c) : sock(s), client(std::move(c)) {}
    socket_t sock;
    std::string client;
    /// head: waiting for its head (the only stage whose place can be taken); judging: its head
    /// read, its share not yet decided; then served as a request without or with the token.
    enum class Stage { head, judging, anonymous, token } stage = Stage::head;
    std::atomic<bool> shed{false};  ///< its place was taken: answer 503 and close
  };
  using SlotRef = std::list<Slot>::iterator;
  /// What a client holds (shed slots not counted).
  struct Held {
    int open = 0, anonymous = 0;
  };

  bool process_and_close_socket(socket_t sock) override;
  /// Counts the connection against the caps, taking the place of a slow one when a cap is
  /// reached; nullopt (nothing counted, `why` set) when no place can be had.
  std::optional<SlotRef> admit(socket_t sock, const std::string& client, Slot::Stage stage,
                               std::string& why);
  /// The oldest slot still reading its head: of `client`, or (empty) of the client holding the
  /// most connections. Under mu_.
  std::optional<SlotRef> victim(const std::string& client);
  /// A head was read: 0 when it may be served, else a refusal (shed, or the token's share).
  HeadVerdict judge(SlotRef slot, bool token);
  void release(SlotRef slot);
  /// Reads until the head is complete: its verdict, with the bytes read in `buffer`.
  HeadVerdict read_head(socket_t sock, std::chrono::steady_clock::time_point deadline,
                        const std::atomic<bool>& shed, std::string& buffer) const;
  void refuse(socket_t sock, const HeadVerdict& v) const;
  /// Serves one admitted connection: the rest of its head (`buffer`: what came before), the
  /// verdict, httplib.
  void serve(SlotRef slot, std::chrono::steady_clock::time_point deadline, std::string buffer);

  ConnectionLimits limits_;
  std::function<void(int)> refused_;
  std::function<bool(std::string_view)> token_holder_;
  std::mutex mu_;
  std::list<Slot> slots_;  ///< admitted, oldest first (a shed one until its thread ends)
  std::map<std::string, Held> held_;
  Held all_;
};

}  // namespace station::http
