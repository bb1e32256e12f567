// Issue 34 point 6: the HTTP service's caps with real sockets on loopback. Every loopback address
// is one client; a connection beyond a cap takes the place of the oldest one still waiting for
// its head; requests without the token never take the token holder's share, so the token holder
// is served while the service is full (the daemon under attack: tests/web/api_limits_test.py).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "station/http/bounded_server.hpp"

namespace sh = station::http;

namespace {

constexpr const char* kToken = "Bearer 0123456789abcdef0123456789abcdef";

/// A connected socket to 127.0.0.1:port (reads time out after 10 s: a failure, never a hang).
int connect_to(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{10, 0};
  ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  EXPECT_EQ(::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  return s;
}

void send_all(int s, const std::string& text) {
  ASSERT_EQ(::send(s, text.data(), text.size(), MSG_NOSIGNAL), static_cast<ssize_t>(text.size()));
}

/// What the server answered until it closed (or 10 s passed).
std::string answer(int s) {
  std::string got;
  char buf[4096];
  for (ssize_t n; (n = ::recv(s, buf, sizeof buf, 0)) > 0;) got.append(buf, static_cast<size_t>(n));
  ::close(s);
  return got;
}

std::string get(const std::string& path, bool token) {
  return "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" +
         (token ? std::string("Authorization: ") + kToken + "\r\n" : "") + "\r\n";
}

/// A bounded server of 6 connections, all from one client, 2 kept for the token holder; /hold
/// answers once released, /ok at once.
struct SmallServer {
  SmallServer()
      : server({{}, std::chrono::milliseconds(10'000), 6, 6, 2}, nullptr,
               [](std::string_view h) { return h == kToken; }) {
    server.Get("/hold", [this](const httplib::Request&, httplib::Response& res) {
      std::unique_lock lock(mu);
      ++holding;
      cv.notify_all();
      cv.wait(lock, [this] { return released; });
      res.set_content("held", "text/plain");
    });
    server.Get("/ok", [](const httplib::Request&, httplib::Response& res) {
      res.set_content("ok", "text/plain");
    });
    port = server.bind_to_any_port("127.0.0.1");
    server.set_backlog(16);
    thread = std::thread([this] { server.listen_after_bind(); });
  }
  ~SmallServer() {
    release();
    server.stop();
    thread.join();
  }
  void release() {
    std::lock_guard lock(mu);
    released = true;
    cv.notify_all();
  }
  void wait_holding(int n) {
    std::unique_lock lock(mu);
    cv.wait(lock, [&] { return holding >= n; });
  }
  /// Until the server counts `n` connections (each is counted by its own thread).
  void wait_open(int n) {
    while (server.open_connections() != n)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }

  sh::BoundedServer server;
  int port = 0;
  std::thread thread;
  std::mutex mu;
  std::condition_variable cv;
  int holding = 0;
  bool released = false;
};

}  // namespace

TEST(BoundedServer, EveryLoopbackAddressIsOneClient) {
  for (const char* a : {"127.0.0.1", "127.0.0.2", "127.255.1.3", "::1", "::ffff:127.0.0.3"})
    EXPECT_EQ(sh::client_of(a), "loopback") << a;
  EXPECT_EQ(sh::client_of("192.0.2.7"), "192.0.2.7");
  EXPECT_EQ(sh::client_of("::ffff:192.0.2.7"), "192.0.2.7");
  EXPECT_EQ(sh::client_of("128.0.0.1"), "128.0.0.1");
  EXPECT_EQ(sh::client_of("fd00::2"), "fd00::2");
}

// The service full of requests without the token (4 being served, the most they may hold of 6)
// and of slow connections that never send a head: another such request is 503 naming the
// token holder's share, and the token holder's is served, taking the place of the oldest slow
// connection (answered 503).
TEST(BoundedServer, TheTokenHolderIsServedWhileTheServiceIsFull) {
  SmallServer s;
  std::vector<int> held;
  for (int i = 0; i < 4; ++i) {
    held.push_back(connect_to(s.port));
    send_all(held.back(), get("/hold", false));
  }
  s.wait_holding(4);
  const int slow1 = connect_to(s.port);
  s.wait_open(5);
  const int slow2 = connect_to(s.port);
  s.wait_open(6);

  const int anonymous = connect_to(s.port);
  send_all(anonymous, get("/ok", false));
  const std::string refused = answer(anonymous);
  EXPECT_NE(refused.find("HTTP/1.1 503"), std::string::npos) << refused;
  EXPECT_NE(refused.find("kept for the token holder"), std::string::npos) << refused;
  EXPECT_NE(answer(slow1).find("HTTP/1.1 503"), std::string::npos);  // its place was taken

  const int slow3 = connect_to(s.port);
  s.wait_open(6);  // full again: 4 held, slow2, slow3
  const int holder = connect_to(s.port);
  send_all(holder, get("/ok", true));
  const std::string served = answer(holder);
  EXPECT_NE(served.find("HTTP/1.1 200"), std::string::npos) << served;
  EXPECT_NE(answer(slow2).find("took this one's place"), std::string::npos);

  s.release();
  for (const int h : held) EXPECT_NE(answer(h).find("HTTP/1.1 200"), std::string::npos);
  ::close(slow3);
}

// Every slot serving a request (4 without the token, 2 with it): nothing to take the place of,
// so a new connection is answered 503 at once, before any head.
TEST(BoundedServer, ANewConnectionIs503WhenEverySlotIsServing) {
  SmallServer s;
  std::vector<int> held;
  for (int i = 0; i < 6; ++i) {
    held.push_back(connect_to(s.port));
    send_all(held.back(), get("/hold", i >= 4));
  }
  s.wait_holding(6);
  const int late = connect_to(s.port);
  const std::string got = answer(late);
  EXPECT_NE(got.find("HTTP/1.1 503"), std::string::npos) << got;
  EXPECT_NE(got.find("connections from loopback are being served"), std::string::npos) << got;
  s.release();
  for (const int h : held) EXPECT_NE(answer(h).find("HTTP/1.1 200"), std::string::npos);
}
