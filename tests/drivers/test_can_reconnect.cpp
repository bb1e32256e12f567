// ReconnectingCanTransport over real AF_UNIX SEQPACKET sockets: a bus peer that goes away and
// comes back on the same path is reconnected with back-off; an inherited fd says it cannot be.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <stdexcept>
#include <string>

#include "drivers/can/reconnecting_transport.hpp"
#include "drivers/counters/counter_frames.hpp"
#include "tests/drivers/manual_clock.hpp"

using namespace station::drivers;
using namespace std::chrono_literals;
using station::testing_support::ManualClock;

namespace {

// The bus side: a listening SEQPACKET socket at `path` (unlinked again by close()).
class Listener {
 public:
  explicit Listener(std::string path) : path_(std::move(path)) {
    ::unlink(path_.c_str());
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path_.c_str(), sizeof addr.sun_path - 1);
    fd_ = UniqueFd(::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0));
    if (::bind(fd_.get(), reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(fd_.get(), 4) != 0)
      throw std::runtime_error("listen " + path_);
  }
  ~Listener() { ::unlink(path_.c_str()); }
  // The next station connection (waits at most 1 s).
  UniqueFd accept() {
    pollfd p{fd_.get(), POLLIN, 0};
    if (::poll(&p, 1, 1000) != 1) return UniqueFd();
    return UniqueFd(::accept4(fd_.get(), nullptr, nullptr, SOCK_CLOEXEC));
  }

 private:
  std::string path_;
  UniqueFd fd_;
};

// One SYNC received by the bus side (a timed-out read gives latch 255).
std::uint8_t read_sync(int fd) {
  pollfd p{fd, POLLIN, 0};
  can_frame f{};
  if (::poll(&p, 1, 1000) != 1 || ::recv(fd, &f, sizeof f, 0) != sizeof f) return 255;
  auto s = counters::decode_sync(f);
  return s ? s.value().latch_seq : 255;
}

}  // namespace

TEST(CanReconnect, UnixPeerThatGoesAwayAndComesBackIsReconnected) {
  const std::string path = ::testing::TempDir() + "can-reconnect-" + std::to_string(getpid());
  ManualClock clock;
  can::CanOpenOptions opt;
  opt.clock = &clock;
  can::ReconnectingCanTransport t(can::parse_can_spec("unix:" + path), opt);
  auto bus = std::make_unique<Listener>(path);
  ASSERT_TRUE(t.send(counters::encode(counters::SyncFrame{1}))) << "first use opens the link";
  auto peer = bus->accept();
  ASSERT_EQ(read_sync(peer.get()), 1);
  // The bus goes away: its connection closes and nothing listens on the path any more.
  peer.reset();
  bus.reset();
  auto lost = t.receive(10ms);
  ASSERT_FALSE(lost);
  EXPECT_EQ(lost.error().kind, ErrorKind::disconnected) << lost.error().message;
  EXPECT_FALSE(t.link_up());
  auto refused = t.send(counters::encode(counters::SyncFrame{2}));  // immediate attempt fails
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().kind, ErrorKind::disconnected);
  bus = std::make_unique<Listener>(path);  // back on the same path
  auto waiting = t.send(counters::encode(counters::SyncFrame{3}));
  ASSERT_FALSE(waiting) << "no attempt is due 0 s after a failed one";
  EXPECT_NE(waiting.error().message.find("next attempt in 0.5 s"), std::string::npos)
      << waiting.error().message;
  clock.advance(0.5);
  ASSERT_TRUE(t.send(counters::encode(counters::SyncFrame{4})));
  EXPECT_TRUE(t.link_up());
  EXPECT_EQ(t.reconnects(), 1);
  peer = bus->accept();
  ASSERT_TRUE(peer.valid());
  EXPECT_EQ(read_sync(peer.get()), 4);  // the frame went out on the new link
  // And frames come back in.
  const can_frame counts = counters::encode(counters::CountsFrame{1, 10, 20});
  ASSERT_EQ(::send(peer.get(), &counts, sizeof counts, 0), static_cast<ssize_t>(sizeof counts));
  auto in = t.receive(1000ms);
  ASSERT_TRUE(in) << in.error().message;
  EXPECT_EQ(in.value().can_id, counts.can_id);
}

TEST(CanReconnect, BackOffDoublesWhileThePeerStaysAway) {
  const std::string path = ::testing::TempDir() + "can-absent-" + std::to_string(getpid());
  ::unlink(path.c_str());
  ManualClock clock;
  can::CanOpenOptions opt;
  opt.clock = &clock;
  can::ReconnectingCanTransport t(can::parse_can_spec("unix:" + path), opt);
  int attempts = 0;
  // Over 16 s of one call per 0.25 s: attempts at 0, 0.5, 1.5, 3.5, 7.5, 15.5 s.
  for (int i = 0; i < 64; ++i, clock.advance(0.25)) {
    auto r = t.send(counters::encode(counters::SyncFrame{0}));
    ASSERT_FALSE(r);
    if (r.error().message.find("next attempt") == std::string::npos) ++attempts;
  }
  EXPECT_EQ(attempts, 6);
}

TEST(CanReconnect, InheritedFdCannotBeReopenedAndSaysSo) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  can::ReconnectingCanTransport t(can::parse_can_spec("fd:" + std::to_string(sv[0])), {});
  ASSERT_TRUE(t.send(counters::encode(counters::SyncFrame{1})));
  ::close(sv[1]);
  for (int i = 0; i < 2; ++i) {  // read again on every call, the same answer each time
    auto r = t.receive(10ms);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().kind, ErrorKind::disconnected);
    EXPECT_NE(r.error().message.find("cannot be reopened"), std::string::npos) << r.error().message;
    EXPECT_TRUE(t.link_up());
  }
}
