// Replies that drip (the `drip` fault): per connection, the bytes still to send and when the next
// one is due, one byte at a time on the wall clock, in order. A server's poll loop asks how long
// it may sleep and sends what is due; it never blocks on a drip. Server thread only.
#pragma once

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <span>

namespace station::sim {

class DripQueue {
 public:
  using Clock = std::chrono::steady_clock;

  /// Queues `bytes` for `fd`, one every `interval_s` after what is queued already.
  void push(int fd, std::span<const std::uint8_t> bytes, double interval_s) {
    auto& q = queues_[fd];
    if (q.bytes.empty()) q.due = Clock::now();
    if (interval_s > 0)  // a reply queued behind a drip that ended drips on with it
      q.interval =
          std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(interval_s));
    q.bytes.insert(q.bytes.end(), bytes.begin(), bytes.end());
  }
  /// True while `fd` has bytes queued (a reply behind them must queue too).
  bool busy(int fd) const {
    const auto it = queues_.find(fd);
    return it != queues_.end() && !it->second.bytes.empty();
  }
  /// How long a poll may sleep before the next byte is due, at most `longest_ms`.
  int poll_ms(int longest_ms) const {
    auto ms = static_cast<std::int64_t>(longest_ms);
    for (const auto& [fd, q] : queues_) {
      if (q.bytes.empty()) continue;
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(q.due - Clock::now());
      ms = std::min<std::int64_t>(ms, std::max<std::int64_t>(0, left.count()));
    }
    return static_cast<int>(ms);
  }
  /// Sends every byte that is due (a closed peer drops its queue).
  void send_due() {
    for (auto& [fd, q] : queues_) {
      while (!q.bytes.empty() && Clock::now() >= q.due) {
        const std::uint8_t b = q.bytes.front();
        ssize_t n = ::send(fd, &b, 1, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n < 0 && errno == ENOTSOCK) n = ::write(fd, &b, 1);
        if (n < 0 && errno == EAGAIN) break;
        if (n < 0) q.bytes.clear();
        if (n <= 0) break;
        q.bytes.pop_front();
        q.due += q.interval;
      }
    }
  }
  /// Drops what was queued for `fd` (its connection closed).
  void forget(int fd) { queues_.erase(fd); }

 private:
  struct Queue {
    std::deque<std::uint8_t> bytes;
    Clock::time_point due{};
    Clock::duration interval{};
  };
  std::map<int, Queue> queues_;
};

}  // namespace station::sim
