// Issue 37: a device reading's block reads pipelined on Modbus TCP (`modbus_pipeline`): every
// request on the wire before the first reply, the replies matched by transaction id (Modbus
// Messaging on TCP/IP Implementation Guide v1.0b §3.1.3), and every failure the one the same
// request read alone would have had. Against a scripted peer on loopback (it sees what is on the
// wire, answers out of order, leaves one out, garbles one) and against the simulator's server.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/modbus/modbus_adu.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/modbus_frame.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "drivers/registry/dialects.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace {

namespace dr = station::drivers;
namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;
using Bytes = std::vector<std::uint8_t>;

constexpr double kTimeoutS = 0.3;
constexpr int kPipeline = 8;

struct RecordingTap : dr::Tap {
  std::vector<dr::TapRecord> records;
  void on_exchange(const dr::TapRecord& r) noexcept override { records.push_back(r); }
};

// What the peer does with the n-th request it reads (from 0, in arrival order).
enum class Answer { ok, silent, wrong_id, short_reply, exception };

// A read reply to request frame `q` whose register at address A holds A (a value that tells which
// request a reply answers).
Bytes reply_to(const Bytes& q) {
  const int addr = (q[8] << 8) | q[9], count = (q[10] << 8) | q[11];
  const int length = 3 + 2 * count;
  Bytes r{q[0],
          q[1],
          0,
          0,
          static_cast<std::uint8_t>(length >> 8),
          static_cast<std::uint8_t>(length & 0xFF),
          q[6],
          q[7],
          static_cast<std::uint8_t>(2 * count)};
  for (int i = 0; i < count; ++i) {
    r.push_back(static_cast<std::uint8_t>((addr + i) >> 8));
    r.push_back(static_cast<std::uint8_t>((addr + i) & 0xFF));
  }
  return r;
}

Bytes answer(const Bytes& q, Answer a) {
  Bytes r = reply_to(q);
  switch (a) {
    case Answer::wrong_id:
      r[1] = static_cast<std::uint8_t>(r[1] + 100);
      return r;
    case Answer::short_reply:  // a byte count of 0 for one register asked
      return {q[0], q[1], 0, 0, 0, 3, q[6], q[7], 0};
    case Answer::exception:  // 02: illegal data address
      return {q[0], q[1], 0, 0, 0, 3, q[6], static_cast<std::uint8_t>(q[7] | 0x80), 2};
    default:
      return r;
  }
}

// A Modbus TCP peer on 127.0.0.1 run by a script on its own thread: it reads whole request
// frames as they come and keeps every byte it was sent.
class ScriptedPeer {
 public:
  using Script = std::function<void(ScriptedPeer&)>;
  explicit ScriptedPeer(Script script) : script_(std::move(script)) {
    listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    EXPECT_EQ(bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    EXPECT_EQ(listen(listen_fd_, 1), 0);
    EXPECT_EQ(getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len), 0);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] {
      pollfd p{listen_fd_, POLLIN, 0};
      if (poll(&p, 1, 10000) != 1) return;
      fd_ = accept(listen_fd_, nullptr, nullptr);
      script_(*this);
    });
  }
  ~ScriptedPeer() {
    join();
    if (fd_ != -1) close(fd_);
    close(listen_fd_);
  }
  /// Waits for the script to end; `received` and `reads` are whole after it.
  void join() {
    if (thread_.joinable()) thread_.join();
  }
  std::string endpoint() const { return "tcp://127.0.0.1:" + std::to_string(port_); }

  /// The next request frame within `wait_ms` (empty: none came or the client hung up).
  Bytes next_frame(int wait_ms = 5000) {
    for (;;) {
      if (buf_.size() >= 6 && buf_.size() >= 6u + ((buf_[4] << 8) | buf_[5])) {
        const auto n = static_cast<std::ptrdiff_t>(6 + ((buf_[4] << 8) | buf_[5]));
        Bytes f(buf_.begin(), buf_.begin() + n);
        buf_.erase(buf_.begin(), buf_.begin() + n);
        return f;
      }
      pollfd p{fd_, POLLIN, 0};
      std::uint8_t chunk[512];
      if (poll(&p, 1, wait_ms) != 1) return {};
      const ssize_t n = recv(fd_, chunk, sizeof chunk, 0);
      if (n <= 0) return {};
      reads.push_back(static_cast<std::size_t>(n));
      received.insert(received.end(), chunk, chunk + n);
      buf_.insert(buf_.end(), chunk, chunk + n);
    }
  }
  void send_bytes(const Bytes& b) const { (void)send(fd_, b.data(), b.size(), MSG_NOSIGNAL); }
  /// Answers each request as it comes, the n-th as `answers[n]` says (ok past the end), until
  /// `total` requests were read or the client stops sending.
  void answer_each(const std::vector<Answer>& answers, std::size_t total) {
    for (std::size_t n = 0; n < total; ++n) {
      const Bytes q = next_frame();
      if (q.empty()) return;
      const Answer a = n < answers.size() ? answers[n] : Answer::ok;
      if (a != Answer::silent) send_bytes(answer(q, a));
    }
  }

  Bytes received;                  ///< every byte the client sent, in order
  std::vector<std::size_t> reads;  ///< the size of each recv that took them

 private:
  Script script_;
  int listen_fd_ = -1, fd_ = -1, port_ = 0;
  Bytes buf_;
  std::thread thread_;
};

// The generic PLC chamber's live points (alarms 110, air 100, setpoint 300): three block reads.
struct LiveRead {
  std::vector<mb::Point> points{cm::generic_plc().at(cm::kAlarms), cm::generic_plc().at(cm::kAir),
                                cm::generic_plc().at(cm::kSetpoint)};
  std::vector<mb::ReadBlock> plan = mb::plan_reads(points, 0);
};

// The live points as the peer serves them (register A holds A): alarm bits 110, air 100 x 0.1 C,
// setpoint 300 x 0.1 C (the map's int16 tenths; decoded by a multiplication, so to a rounding).
void expect_live_values(const std::vector<double>& v) {
  ASSERT_EQ(v.size(), 3u);
  EXPECT_DOUBLE_EQ(v[0], 110.0);
  EXPECT_DOUBLE_EQ(v[1], 10.0);
  EXPECT_DOUBLE_EQ(v[2], 30.0);
}

std::unique_ptr<mb::ModbusClient> client_for(const std::string& endpoint, int pipeline,
                                             dr::Tap* tap = nullptr) {
  auto c = std::make_unique<mb::ModbusClient>("chamber", mb::parse_endpoint(endpoint), kTimeoutS);
  c->set_pipeline(pipeline);
  c->set_tap(tap);
  return c;
}

// The request frames a client sends for `plan` from transaction id `first_tid`, in plan order.
Bytes request_bytes(const std::vector<mb::ReadBlock>& plan, std::uint16_t first_tid) {
  Bytes out;
  for (const auto& b : plan) {
    const auto f = mb::request_frame(
        mb::Framing::tcp, first_tid++,
        mb::read_request_adu(b.unit_id, static_cast<int>(b.function), b.start, b.count));
    out.insert(out.end(), f.begin(), f.end());
  }
  return out;
}

// What a tap saw, without its times: direction, kind, bytes.
std::vector<std::string> seen(const RecordingTap& tap) {
  std::vector<std::string> out;
  for (const auto& r : tap.records) {
    std::string line = std::to_string(static_cast<int>(r.direction)) + " " + r.kind + " ";
    for (auto b : r.bytes) line += std::to_string(b) + ",";
    out.push_back(line);
  }
  return out;
}

}  // namespace

// All three requests reach the peer before it answers any (it reads three frames first: a client
// waiting for each reply would leave it waiting), and it answers them last to first: each value
// lands at its own point.
TEST(ModbusPipeline, RequestsAreOnTheWireTogetherAndRepliesMatchByIdInAnyOrder) {
  LiveRead live;
  ScriptedPeer peer([](ScriptedPeer& p) {
    std::vector<Bytes> qs;
    for (int i = 0; i < 3; ++i) qs.push_back(p.next_frame());
    for (auto q = qs.rbegin(); q != qs.rend(); ++q)
      if (!q->empty()) p.send_bytes(reply_to(*q));
  });
  auto client = client_for(peer.endpoint(), kPipeline);
  const auto v = client->read_points(live.points, live.plan);
  ASSERT_TRUE(v) << v.error().message;
  expect_live_values(v.value());
}

// The pipelined and the one-at-a-time client put the same bytes on the wire in the same order;
// one at a time, the peer reads each request alone (nothing more is sent before its reply),
// pipelined all three in one read; the tap records are the same either way (a session recorded
// pipelined replays on a link that reads one at a time).
TEST(ModbusPipeline, OffIsTodaysBytesAndOrderAndTheTapIsTheSameEitherWay) {
  LiveRead live;
  Bytes wire[2];
  std::vector<std::size_t> reads[2];
  RecordingTap taps[2];
  for (int mode = 0; mode < 2; ++mode) {
    ScriptedPeer peer([](ScriptedPeer& p) { p.answer_each({}, 3); });
    auto client = client_for(peer.endpoint(), mode == 0 ? 1 : kPipeline, &taps[mode]);
    const auto v = client->read_points(live.points, live.plan);
    ASSERT_TRUE(v) << v.error().message;
    expect_live_values(v.value());
    client->disconnect();
    peer.join();
    wire[mode] = peer.received;
    reads[mode] = peer.reads;
  }
  EXPECT_EQ(wire[0], request_bytes(live.plan, 1));
  EXPECT_EQ(wire[1], wire[0]);
  EXPECT_EQ(reads[0], (std::vector<std::size_t>{12, 12, 12}));  // one request, its reply, ...
  EXPECT_EQ(reads[1], (std::vector<std::size_t>{36}));          // all three in one send
  EXPECT_EQ(seen(taps[1]), seen(taps[0]));
  EXPECT_EQ(taps[0].records.size(), 8u);  // connect, tx and rx of each, disconnect
}

namespace {

struct Outcome {
  dr::ErrorKind kind{};
  std::string message;
  std::vector<std::string> tap;
  bool next_read_ok = false;
  std::vector<double> next_values;
};

// The live read against a peer that answers the second request as `a` (and every other one, and
// the three of a second read, properly), with the client one at a time or pipelined.
Outcome second_request_answered(Answer a, int pipeline) {
  LiveRead live;
  RecordingTap tap;
  ScriptedPeer peer([a](ScriptedPeer& p) { p.answer_each({Answer::ok, a}, 6); });
  auto client = client_for(peer.endpoint(), pipeline, &tap);
  Outcome o;
  const auto first = client->read_points(live.points, live.plan);
  EXPECT_FALSE(first) << "answer " << static_cast<int>(a);
  if (first) return o;
  o.kind = first.error().kind;
  o.message = first.error().message;
  o.tap = seen(tap);
  const auto next = client->read_points(live.points, live.plan);
  o.next_read_ok = next.ok();
  if (next) o.next_values = next.value();
  client->disconnect();
  return o;
}

}  // namespace

// A missing reply, a reply with another transaction id, a short reply and an exception for the
// second request: the pipelined read fails as the one-at-a-time read does (same kind, same
// message naming the second request, same tap records up to it), and the next read is answered
// right (a reply to the abandoned third request, coming late, is dropped by its id, never read as
// another request's).
TEST(ModbusPipeline, AFailedReplyIsTheSameErrorAsOneAtATimeAndTheNextReadIsRight) {
  const std::pair<Answer, dr::ErrorKind> cases[] = {{Answer::silent, dr::ErrorKind::timeout},
                                                    {Answer::wrong_id, dr::ErrorKind::protocol},
                                                    {Answer::short_reply, dr::ErrorKind::protocol},
                                                    {Answer::exception, dr::ErrorKind::exception}};
  for (const auto& [a, kind] : cases) {
    SCOPED_TRACE("answer " + std::to_string(static_cast<int>(a)));
    const Outcome alone = second_request_answered(a, 1);
    const Outcome piped = second_request_answered(a, kPipeline);
    EXPECT_EQ(alone.kind, kind) << alone.message;
    EXPECT_EQ(piped.kind, alone.kind) << piped.message;
    EXPECT_EQ(piped.message, alone.message);
    EXPECT_NE(piped.message.find("addr=110"), std::string::npos) << piped.message;
    EXPECT_EQ(piped.tap, alone.tap);
    EXPECT_TRUE(alone.next_read_ok);
    EXPECT_TRUE(piped.next_read_ok);
    expect_live_values(piped.next_values);
  }
}

// The whole batch has one deadline: a peer that reads the requests and never answers ends the
// read by the timeout, once (not once a request), as a timeout.
TEST(ModbusPipeline, ASilentPeerEndsTheBatchAtOneTimeout) {
  LiveRead live;
  ScriptedPeer peer([](ScriptedPeer& p) {
    p.answer_each({Answer::silent, Answer::silent, Answer::silent}, 3);
  });
  auto client = client_for(peer.endpoint(), kPipeline);
  const auto t0 = std::chrono::steady_clock::now();
  const auto v = client->read_points(live.points, live.plan);
  const double waited_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().kind, dr::ErrorKind::timeout) << v.error().message;
  EXPECT_NE(v.error().message.find("addr=100"), std::string::npos) << v.error().message;
  EXPECT_GE(waited_s, kTimeoutS * 0.9);  // a lower bound only: it waited for the replies
  client->disconnect();
}
