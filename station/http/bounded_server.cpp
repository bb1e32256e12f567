// The bounded server (see bounded_server.hpp): a thread per connection up to a total, a cap per
// client (all loopback one client), a slow connection's place taken when a cap is reached, a
// share kept for the token holder, one request per connection whose head is read here under a
// deadline and the head rules, then handed to httplib with the bytes already read in front of
// the socket.
#include "station/http/bounded_server.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <nlohmann/json.hpp>
#include <thread>

namespace station::http {

namespace {

using Clock = std::chrono::steady_clock;

/// Set on a connection's thread when no thread may be had for it: answer 503 and close.
thread_local bool over_capacity = false;
/// Set by exempt_from_response_deadline() for the response being written on this thread.
thread_local bool endless_response = false;

/// A thread per connection (a slow client holds only its own; the caps are BoundedServer's, a
/// connection beyond them gets a thread that only answers) while fewer than `max_threads` run;
/// beyond, or when no thread can be had, the connection is answered on the accept thread
/// without waiting (over_capacity). shutdown() waits for every thread.
class ConnectionQueue final : public httplib::TaskQueue {
 public:
  explicit ConnectionQueue(int max_threads) : max_threads_(max_threads) {}
  void enqueue(std::function<void()> fn) override {
    std::unique_lock lock(state_->mu);
    const bool room = state_->running < max_threads_;
    if (room) ++state_->running;
    lock.unlock();
    if (room) {
      try {
        std::thread(
            [st = state_](const std::function<void()>& f) {
              f();
              st->done();
            },
            std::move(fn))
            .detach();
        return;
      } catch (const std::system_error&) {  // no thread to be had
        state_->done();
      }
    }
    over_capacity = true;
    fn();
    over_capacity = false;
  }
  void shutdown() override {
    std::unique_lock lock(state_->mu);
    state_->idle.wait(lock, [this] { return state_->running == 0; });
  }

 private:
  struct State {  // shared with the threads: the last one may end after the queue is gone
    std::mutex mu;
    std::condition_variable idle;
    int running = 0;
    void done() {
      std::lock_guard lock(mu);
      if (--running == 0) idle.notify_all();
    }
  };
  int max_threads_;
  std::shared_ptr<State> state_ = std::make_shared<State>();
};

std::string address_of(const sockaddr_storage& sa) {
  char text[INET6_ADDRSTRLEN] = "";
  const void* in =
      sa.ss_family == AF_INET6
          ? static_cast<const void*>(&reinterpret_cast<const sockaddr_in6&>(sa).sin6_addr)
          : static_cast<const void*>(&reinterpret_cast<const sockaddr_in&>(sa).sin_addr);
  return ::inet_ntop(sa.ss_family, in, text, sizeof text) != nullptr ? text : "";
}

int port_of(const sockaddr_storage& sa) {
  return ntohs(sa.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6&>(sa).sin6_port
                                        : reinterpret_cast<const sockaddr_in&>(sa).sin_port);
}

/// Waits for `events` on `sock` until `until`; true when they came.
bool wait_for(socket_t sock, short events, Clock::time_point until) {
  pollfd p{sock, events, 0};
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
  if (left.count() <= 0) return false;
  return ::poll(&p, 1, static_cast<int>(left.count())) > 0 && (p.revents & events) != 0;
}

/// The socket as httplib reads it: the bytes already read first, then reads until the request's
/// deadline (a body trickled past it ends the request). Writes never block (MSG_DONTWAIT: a
/// blocking send of a large piece would wait for the reader however slow) and end at the
/// response's deadline: kSendAllowance after the later of the request's deadline and the first
/// write, plus a second per kMinSendBytesPerS bytes sent so far. A reader slower than that
/// throughput falls behind its deadline and is cut off, whatever it reads each few seconds; one
/// at least that fast is served to the end. An endless response (exempt_from_response_deadline:
/// the event stream, capped by its handler) keeps a per-write timeout instead.
class DeadlineStream final : public httplib::Stream {
 public:
  /// Time for an answer's first bytes to leave (the per-write timeout this replaced).
  static constexpr auto kSendAllowance = std::chrono::seconds(5);
  /// The slowest reader served to the end: 8 KiB/s (64 kbit/s, a poor mobile link) sends the
  /// largest answer, dygraphs' 430 kB, in under a minute; a reader below it holds a place for
  /// little more than kSendAllowance past the request's deadline.
  static constexpr double kMinSendBytesPerS = 8 * 1024;

  DeadlineStream(socket_t sock, std::string read, Clock::time_point deadline)
      : sock_(sock), read_(std::move(read)), deadline_(deadline) {}
  bool is_readable() const override {
    return at_ < read_.size() || wait_for(sock_, POLLIN, deadline_);
  }
  bool is_writable() const override { return wait_for(sock_, POLLOUT, send_deadline()); }
  ssize_t read(char* ptr, size_t size) override {
    if (at_ < read_.size()) {
      const std::size_t n = std::min(size, read_.size() - at_);
      std::copy_n(read_.data() + at_, n, ptr);
      at_ += n;
      return static_cast<ssize_t>(n);
    }
    return wait_for(sock_, POLLIN, deadline_) ? ::recv(sock_, ptr, size, 0) : -1;
  }
  ssize_t write(const char* ptr, size_t size) override {
    if (!first_write_) first_write_ = Clock::now();
    if (!is_writable()) return -1;
    const ssize_t n = ::send(sock_, ptr, size, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return 0;  // httplib writes again
    if (n > 0) sent_bytes_ += static_cast<std::size_t>(n);
    return n;
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    name_of(::getpeername, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    name_of(::getsockname, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  Clock::time_point send_deadline() const {
    const auto now = Clock::now();
    if (endless_response) return now + kSendAllowance;
    const auto start = first_write_.value_or(now);
    const auto allowance = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(static_cast<double>(sent_bytes_) / kMinSendBytesPerS));
    return std::max(deadline_, start + kSendAllowance) + allowance;
  }
  template <class F>
  void name_of(F get, std::string& ip, int& port) const {
    sockaddr_storage sa{};
    socklen_t len = sizeof sa;
    if (get(sock_, reinterpret_cast<sockaddr*>(&sa), &len) != 0) return;
    ip = address_of(sa);
    port = port_of(sa);
  }
  socket_t sock_;
  std::string read_;
  std::size_t at_ = 0;
  Clock::time_point deadline_;
  std::optional<Clock::time_point> first_write_;
  std::size_t sent_bytes_ = 0;
};

const char* reason_phrase(int status) {
  switch (status) {
    case 400:
      return "Bad Request";
    case 408:
      return "Request Timeout";
    case 414:
      return "URI Too Long";
    case 431:
      return "Request Header Fields Too Large";
    default:
      return "Service Unavailable";
  }
}

}  // namespace

std::string client_of(std::string_view address) {
  std::string a(address);
  if (a.starts_with("::ffff:") && a.find('.') != std::string::npos) a.erase(0, 7);
  in_addr v4{};
  if (::inet_pton(AF_INET, a.c_str(), &v4) == 1)
    return (ntohl(v4.s_addr) >> 24) == 127 ? "loopback" : a;
  in6_addr v6{};
  if (::inet_pton(AF_INET6, a.c_str(), &v6) == 1 && IN6_IS_ADDR_LOOPBACK(&v6)) return "loopback";
  return a;
}

void exempt_from_response_deadline() {
  endless_response = true;
}

BoundedServer::BoundedServer(ConnectionLimits limits, std::function<void(int)> refused,
                             std::function<bool(std::string_view)> token_holder)
    : limits_(limits), refused_(std::move(refused)), token_holder_(std::move(token_holder)) {
  new_task_queue = [max = kThreadsPerPlace * limits_.max_connections] {
    return new ConnectionQueue(max);
  };
}

void BoundedServer::set_backlog(int connections) {
  if (svr_sock_ != INVALID_SOCKET) ::listen(svr_sock_, connections);
}

int BoundedServer::open_connections() {
  std::lock_guard lock(mu_);
  return all_.open;
}

std::optional<BoundedServer::SlotRef> BoundedServer::victim(const std::string& client) {
  std::optional<SlotRef> best;
  int most = 0;
  for (auto it = slots_.begin(); it != slots_.end(); ++it) {
    if (it->stage != Slot::Stage::head || it->shed.load()) continue;
    if (!client.empty() && it->client != client) continue;
    const int held = held_[it->client].open;  // oldest first: a tie keeps the older one
    if (held > most) best = it, most = held;
  }
  return best;
}

std::optional<BoundedServer::SlotRef> BoundedServer::admit(socket_t sock, const std::string& client,
                                                           Slot::Stage stage, std::string& why) {
  std::lock_guard lock(mu_);
  const bool client_full = held_[client].open >= limits_.max_per_client;
  const bool all_full = all_.open >= limits_.max_connections;
  if (client_full || all_full) {
    const auto v = victim(client_full ? client : std::string());
    if (!v) {
      if (held_[client].open == 0) held_.erase(client);
      why = client_full ? fmt::format("{} connections from {} are being served",
                                      limits_.max_per_client, client)
                        : fmt::format("{} connections are being served", limits_.max_connections);
      return std::nullopt;
    }
    // Its place is taken: it stops counting now, and its thread answers 503 within a poll.
    (*v)->shed.store(true);
    --all_.open;
    if (--held_[(*v)->client].open == 0) held_.erase((*v)->client);
    ::shutdown((*v)->sock, SHUT_RD);
  }
  ++all_.open;
  ++held_[client].open;
  const auto slot = slots_.emplace(slots_.end(), sock, client);
  slot->stage = stage;
  return slot;
}

HeadVerdict BoundedServer::judge(SlotRef slot, bool token) {
  std::lock_guard lock(mu_);
  if (slot->shed.load())
    return {503, "the service is full: a newer connection took this one's place"};
  if (token) {
    slot->stage = Slot::Stage::token;
    return {};
  }
  Held& mine = held_[slot->client];
  const int all_max = limits_.max_connections - limits_.token_reserve;
  const int client_max = limits_.max_per_client - limits_.token_reserve;
  if (all_.anonymous >= all_max || mine.anonymous >= client_max)
    return {503, fmt::format("{} requests without the API token are being served{}; the other {} "
                             "connections are kept for the token holder",
                             all_.anonymous >= all_max ? all_max : client_max,
                             all_.anonymous >= all_max ? "" : " from " + slot->client,
                             limits_.token_reserve)};
  slot->stage = Slot::Stage::anonymous;
  ++all_.anonymous;
  ++mine.anonymous;
  return {};
}

void BoundedServer::release(SlotRef slot) {
  std::lock_guard lock(mu_);
  if (!slot->shed.load()) {
    Held& mine = held_[slot->client];
    const int anonymous = slot->stage == Slot::Stage::anonymous ? 1 : 0;
    all_.open -= 1, all_.anonymous -= anonymous;
    mine.open -= 1, mine.anonymous -= anonymous;
    if (mine.open == 0) held_.erase(slot->client);
  }
  slots_.erase(slot);
}

HeadVerdict BoundedServer::read_head(socket_t sock, Clock::time_point deadline,
                                     const std::atomic<bool>& shed, std::string& buffer) const {
  char chunk[4096];
  while (true) {
    if (const auto end = head_end(buffer)) {
      return check_request_head(std::string_view(buffer).substr(0, *end), limits_.head);
    }
    if (buffer.size() > limits_.head.max_bytes) return oversized_head(buffer, limits_.head);
    // In slices, so that a stopping server does not wait out a slow client's deadline.
    const auto slice = std::min(deadline, Clock::now() + std::chrono::milliseconds(100));
    if (!is_running()) return {-1, "the server is stopping"};
    if (shed.load()) return {503, "the service is full: a newer connection took this one's place"};
    if (Clock::now() >= deadline)
      return {408, fmt::format("the request did not arrive within {} s",
                               limits_.request_deadline.count() / 1000.0)};
    if (!wait_for(sock, POLLIN, slice)) continue;
    const ssize_t n = ::recv(sock, chunk, sizeof chunk, 0);
    if (n == 0 && shed.load()) continue;  // shut down for reading by the shed: answered above
    if (n <= 0) return {-1, "the client closed the connection"};
    buffer.append(chunk, static_cast<std::size_t>(n));
  }
}

void BoundedServer::refuse(socket_t sock, const HeadVerdict& v) const {
  const std::string body = nlohmann::json{{"error", v.reason}}.dump();
  const std::string reply = fmt::format(
      "HTTP/1.1 {} {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n"
      "Connection: close\r\n{}\r\n{}",
      v.status, reason_phrase(v.status), body.size(), v.status == 503 ? "Retry-After: 1\r\n" : "",
      body);
  // On the accept thread (over_capacity) nothing waits: a new socket's buffer takes the reply.
  if (over_capacity || wait_for(sock, POLLOUT, Clock::now() + std::chrono::seconds(1)))
    (void)::send(sock, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  if (refused_) refused_(v.status);
}

void BoundedServer::serve(SlotRef slot, Clock::time_point deadline, std::string buffer) {
  HeadVerdict v;
  if (slot->stage == Slot::Stage::head) v = read_head(slot->sock, deadline, slot->shed, buffer);
  if (v.status == 0) {
    const auto end = head_end(buffer);
    const auto authorization =
        field_value(std::string_view(buffer).substr(0, *end), "Authorization");
    v = judge(slot, authorization && token_holder_ && token_holder_(*authorization));
  }
  if (v.status == 0) {
    DeadlineStream stream(slot->sock, std::move(buffer), deadline);
    bool closed = false;
    endless_response = false;
    process_request(stream, true, closed, nullptr);
    endless_response = false;
  } else if (v.status > 0) {
    refuse(slot->sock, v);
  }
}

bool BoundedServer::process_and_close_socket(socket_t sock) {
  const auto deadline = Clock::now() + limits_.request_deadline;
  sockaddr_storage peer{};
  socklen_t len = sizeof peer;
  const std::string client = client_of(
      ::getpeername(sock, reinterpret_cast<sockaddr*>(&peer), &len) == 0 ? address_of(peer) : "");
  // The head that came with the connection, read before it counts (kFirstBytes): 408 here only
  // means "not whole yet"; a malformed one is answered without taking a place.
  std::string buffer, why;
  const std::atomic<bool> never{false};
  const HeadVerdict first =
      over_capacity
          ? HeadVerdict{503, "too many connections are being answered"}
          : read_head(sock, std::min(deadline, Clock::now() + kFirstBytes), never, buffer);
  const bool whole = first.status == 0;
  if (first.status != 0 && first.status != 408) {
    if (first.status > 0) refuse(sock, first);
  } else if (const auto slot =
                 admit(sock, client, whole ? Slot::Stage::judging : Slot::Stage::head, why)) {
    serve(*slot, deadline, std::move(buffer));
    release(*slot);
  } else {
    refuse(sock, {503, "the service is full: " + why});
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return true;
}

}  // namespace station::http
