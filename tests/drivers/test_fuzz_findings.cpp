// Regression tests for what fuzzing (tests/fuzz, docs/RELIABILITY.md) found in the drivers.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <thread>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/modbus/map_overrides.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/read_plan.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;

// fuzz_register_maps: an override put a float32 at PDU address 65535, and plan_reads then asked
// for registers 65535..65536, past the Modbus address space (tests/fuzz/findings/...).
TEST(FuzzFindings, APointPastRegister65535IsAConfigError) {
  auto map = cm::generic_plc_float();
  mb::PointOverride last{.name = cm::kAir, .address = 65535};
  EXPECT_THROW(mb::apply_overrides(map, {last}), std::invalid_argument);
  mb::PointOverride one_based{.name = cm::kAir, .address = 65535, .one_based = true};
  EXPECT_NO_THROW(mb::apply_overrides(map, {one_based}));  // PDU 65534..65535: the last two
  mb::PointOverride word{.name = cm::kStatus, .address = 65535};
  EXPECT_NO_THROW(mb::apply_overrides(map, {word}));  // one word at the last register
  std::vector<mb::Point> pts;
  for (const auto& [name, p] : map.points()) pts.push_back(p);
  for (const auto& b : mb::plan_reads(pts, 16)) EXPECT_LE(b.start + b.count, 65536);
}

namespace {

// A Modbus TCP "device" that answers the first read with the start of a reply (header, function,
// byte count 4, two of the four data bytes) and then goes silent until the client hangs up.
class HalfReplyDevice {
 public:
  HalfReplyDevice() {
    listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    EXPECT_EQ(bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    EXPECT_EQ(listen(listen_fd_, 1), 0);
    EXPECT_EQ(getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len), 0);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~HalfReplyDevice() {
    thread_.join();
    close(listen_fd_);
  }
  int port() const { return port_; }

 private:
  void serve() {
    pollfd p{listen_fd_, POLLIN, 0};
    if (poll(&p, 1, 10000) != 1) return;
    const int fd = accept(listen_fd_, nullptr, nullptr);
    std::uint8_t req[12];
    if (recv(fd, req, sizeof req, MSG_WAITALL) == static_cast<ssize_t>(sizeof req)) {
      // MBAP (transaction id echoed, length 7 = unit + fc + count + 4 data bytes), then only
      // half the data.
      const std::uint8_t half[] = {req[0], req[1], 0, 0, 0, 7, req[6], req[7], 4, 0x41, 0xC8};
      (void)send(fd, half, sizeof half, MSG_NOSIGNAL);
    }
    pollfd c{fd, POLLIN, 0};
    std::uint8_t b;
    while (poll(&c, 1, 10000) == 1 && recv(fd, &b, 1, 0) > 0) {
    }
    close(fd);
  }
  int listen_fd_ = -1;
  int port_ = 0;
  std::thread thread_;
};

}  // namespace

// fuzz_modbus_replies: a reply that stops halfway held a call for libmodbus's default byte
// timeout (0.5 s) whatever the configured timeout: with 5 ms configured a read took 0.5 s, and
// a long configured timeout was cut to 0.5 s between bytes. The configured timeout now bounds
// every wait of a transaction: with 1.5 s configured the half reply is given the full 1.5 s
// (0.5 s before the fix), and the call still ends with a timeout.
TEST(FuzzFindings, AReplyThatStopsHalfwayIsGivenTheConfiguredTimeout) {
  HalfReplyDevice device;
  mb::ModbusClient client(
      "chamber", mb::parse_endpoint("tcp://127.0.0.1:" + std::to_string(device.port())), 1.5);
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = client.read_registers(mb::FunctionCode::holding, 1, 100, 2);
  const double waited_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, station::drivers::ErrorKind::timeout) << r.error().message;
  EXPECT_GE(waited_s, 1.2);  // a lower bound: cannot be broken by a slow machine
  client.disconnect();
}
