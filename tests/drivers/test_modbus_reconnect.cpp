// ModbusClient reconnects after its server went away and came back (TCP on the same port, RTU on
// a device path that points at a new serial line), with bounded exponential back-off in between.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/common/backoff.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "tests/drivers/manual_clock.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;
using station::drivers::Backoff;
using station::drivers::ErrorKind;
using station::testing_support::ManualClock;

TEST(Backoff, DoublesFromHalfASecondToEightAndResetsOnSuccess) {
  ManualClock clock;
  Backoff b(&clock);
  EXPECT_TRUE(b.due());  // the first attempt after a loss is immediate
  for (const double delay : {0.5, 1.0, 2.0, 4.0, 8.0, 8.0}) {
    b.failed();
    EXPECT_FALSE(b.due());
    EXPECT_DOUBLE_EQ(b.wait_s(), delay);
    clock.advance(delay);
    EXPECT_TRUE(b.due());
  }
  b.succeeded();
  b.failed();
  EXPECT_DOUBLE_EQ(b.wait_s(), 0.5);
}

namespace {

struct Server {
  mb::RegisterMap map = cm::generic_plc();
  station::sim::ChamberSim sim{map};
  station::sim::ModbusServer server{sim};
};

}  // namespace

TEST(ModbusReconnect, TcpServerRestartedOnTheSamePortIsReconnected) {
  auto first = std::make_unique<Server>();
  first->server.start_tcp();
  const int port = first->server.port();
  ManualClock clock;
  mb::ModbusClient client("chamber", mb::TcpEndpoint{"127.0.0.1", port}, 0.3);
  client.set_clock(&clock);
  const mb::Point air = first->map.at(cm::kAir);
  ASSERT_TRUE(client.read(air));
  first.reset();  // the server process is gone: its connections close
  auto lost = client.read(air);
  ASSERT_FALSE(lost);
  EXPECT_EQ(lost.error().kind, ErrorKind::disconnected) << lost.error().message;
  auto refused = client.read(air);  // one immediate attempt: refused, back-off starts
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().kind, ErrorKind::disconnected) << refused.error().message;
  Server second;
  second.server.start_tcp(port);
  auto waiting = client.read(air);  // up again, but no attempt is due for 0.5 s
  ASSERT_FALSE(waiting);
  EXPECT_NE(waiting.error().message.find("next attempt in 0.5 s"), std::string::npos)
      << waiting.error().message;
  EXPECT_EQ(second.server.requests(), 0u);
  clock.advance(0.5);
  auto back = client.read(air);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_DOUBLE_EQ(back.value(), 25.0);
  EXPECT_TRUE(client.connected());
}

// A USB serial adapter that is unplugged and plugged back comes back as a new tty behind the
// same udev name: the client must reopen the path, not keep reading a dead descriptor.
TEST(ModbusReconnect, RtuLineThatVanishedIsReopened) {
  const std::string link = ::testing::TempDir() + "rtu-link-" + std::to_string(getpid());
  auto first = std::make_unique<Server>();
  first->server.start_rtu_pty();
  std::remove(link.c_str());
  ASSERT_EQ(symlink(first->server.pty_path().c_str(), link.c_str()), 0);
  ManualClock clock;
  mb::ModbusClient client("chamber-rtu", mb::RtuEndpoint{link}, 0.2);
  client.set_clock(&clock);
  const mb::Point air = first->map.at(cm::kAir);
  ASSERT_TRUE(client.read(air));
  first.reset();  // the line is gone (pty master closed, like an unplugged adapter)
  std::remove(link.c_str());
  for (int i = 0; i < 3 && client.connected(); ++i) {
    auto r = client.read(air);
    ASSERT_FALSE(r);
  }
  EXPECT_FALSE(client.connected());
  auto missing = client.read(air);  // the path does not exist: back-off starts
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().kind, ErrorKind::disconnected) << missing.error().message;
  Server second;
  second.server.start_rtu_pty();
  ASSERT_EQ(symlink(second.server.pty_path().c_str(), link.c_str()), 0);
  clock.advance(0.5);
  auto back = client.read(air);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_DOUBLE_EQ(back.value(), 25.0);
  std::remove(link.c_str());
}
