// ModbusClient against a real libmodbus server on 127.0.0.1: errors are typed, faults recover.
#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;
using station::drivers::ErrorKind;

namespace {

struct RecordingTap : station::drivers::Tap {
  std::vector<station::drivers::TapRecord> records;
  void on_exchange(const station::drivers::TapRecord& r) noexcept override { records.push_back(r); }
};

class ModbusClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    server.start_tcp();
    client =
        std::make_unique<mb::ModbusClient>("chamber", mb::parse_endpoint(server.endpoint()), 0.3);
  }
  mb::RegisterMap map = cm::generic_plc();
  station::sim::ChamberSim sim{map};
  station::sim::ModbusServer server{sim};
  std::unique_ptr<mb::ModbusClient> client;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TEST_F(ModbusClientTest, ConstructorDoesNoIoAndFirstReadConnects) {
  EXPECT_FALSE(client->connected());
  EXPECT_EQ(server.requests(), 0u);
  auto v = client->read(map.at(cm::kAir));
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_DOUBLE_EQ(v.value(), 25.0);
  EXPECT_TRUE(client->connected());
}

TEST_F(ModbusClientTest, TimeoutIsTypedBoundedAndNextCallWorks) {
  ASSERT_TRUE(client->connect());
  server.inject_timeouts(1);
  auto t0 = std::chrono::steady_clock::now();
  auto v = client->read(map.at(cm::kAir));
  double waited = seconds_since(t0);
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().kind, ErrorKind::timeout) << v.error().message;
  // It waited for the configured 0.3 s and then gave up (bound, not a speed assertion).
  EXPECT_GE(waited, 0.25);
  EXPECT_LT(waited, 3.0);
  auto again = client->read(map.at(cm::kAir));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_DOUBLE_EQ(again.value(), 25.0);
}

TEST_F(ModbusClientTest, ExceptionRepliesAreTypedAsException) {
  server.inject_exception(MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE);
  auto v = client->read(map.at(cm::kAir));
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().kind, ErrorKind::exception);
  EXPECT_NE(v.error().message.find("chamber"), std::string::npos);
  // A genuine ILLEGAL_DATA_ADDRESS: a register beyond the server's table.
  mb::Point beyond{"beyond", 9000};
  auto b = client->read(beyond);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().kind, ErrorKind::exception);
  EXPECT_NE(b.error().message.find("Illegal data address"), std::string::npos) << b.error().message;
  EXPECT_TRUE(client->read(map.at(cm::kAir)));
}

TEST_F(ModbusClientTest, DroppedConnectionIsDisconnectedThenReconnects) {
  ASSERT_TRUE(client->connect());
  server.inject_drop();
  auto v = client->read(map.at(cm::kAir));
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().kind, ErrorKind::disconnected) << v.error().message;
  EXPECT_FALSE(client->connected());
  auto again = client->read(map.at(cm::kAir));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_TRUE(client->connected());
}

TEST_F(ModbusClientTest, ConnectRefusedIsDisconnected) {
  int port = server.port();
  server.stop();
  mb::ModbusClient lonely("chamber", mb::TcpEndpoint{"127.0.0.1", port}, 0.3);
  auto c = lonely.connect();
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().kind, ErrorKind::disconnected) << c.error().message;
  auto r = lonely.read(map.at(cm::kAir));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, ErrorKind::disconnected);
}

TEST_F(ModbusClientTest, WritesRespectAccessAndRange) {
  auto ro = client->write(map.at(cm::kAir), 10.0);
  ASSERT_FALSE(ro);
  EXPECT_EQ(ro.error().kind, ErrorKind::range);
  auto big = client->write(map.at(cm::kSetpoint), 5000.0);  // 50000 raw: not an int16
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().kind, ErrorKind::range);
  EXPECT_EQ(server.requests(), 0u);  // nothing went on the wire
  ASSERT_TRUE(client->write(map.at(cm::kSetpoint), -12.3));
  auto back = client->read(map.at(cm::kSetpoint));
  ASSERT_TRUE(back);
  EXPECT_NEAR(back.value(), -12.3, 1e-9);
}

TEST_F(ModbusClientTest, EveryExchangePassesTheTap) {
  RecordingTap tap;
  client->set_tap(&tap);
  ASSERT_TRUE(client->read(map.at(cm::kAir)));
  ASSERT_GE(tap.records.size(), 3u);  // connect event, tx, rx
  const auto& tx = tap.records[tap.records.size() - 2];
  const auto& rx = tap.records.back();
  EXPECT_EQ(tx.direction, station::drivers::TapDirection::tx);
  // ADUs without framing: unit 1, fc 3, addr 100, count 1; the reply 25.0 C = 250.
  EXPECT_EQ(tx.bytes, (std::vector<std::uint8_t>{1, 3, 0, 100, 0, 1}));
  EXPECT_EQ(rx.bytes, (std::vector<std::uint8_t>{1, 3, 2, 0, 250}));
  EXPECT_GT(rx.wall_time_s, 1.6e9);
  server.inject_timeouts(1);
  ASSERT_FALSE(client->read(map.at(cm::kAir)));
  EXPECT_EQ(tap.records.back().kind, "error");
  // The errno of the failure, big-endian: a timeout.
  EXPECT_EQ(tap.records.back().bytes, (std::vector<std::uint8_t>{0, 0, 0, ETIMEDOUT}));
  // A write carries its values: fc 6, addr, value (a setpoint of 30.0 C = 300). (Copies: the
  // references above dangle once the tap's vector grows.)
  ASSERT_TRUE(client->write(map.at(cm::kSetpoint), 30.0));
  const auto wtx = tap.records[tap.records.size() - 2];
  EXPECT_EQ(wtx.kind, "modbus-write");
  ASSERT_EQ(wtx.bytes.size(), 6u);
  EXPECT_EQ(wtx.bytes[1], 6);
  EXPECT_EQ(wtx.bytes[4], 300 >> 8);
  EXPECT_EQ(wtx.bytes[5], 300 & 0xFF);
}

namespace {

int count_kind(const std::vector<station::drivers::TapRecord>& records, const std::string& kind) {
  int n = 0;
  for (const auto& r : records) n += r.kind == kind ? 1 : 0;
  return n;
}

}  // namespace

// A gateway that rebooted leaves the TCP socket half-open: requests vanish, nothing says
// "disconnected". After kTimeoutsBeforeReconnect timeouts in a row the client must reconnect.
TEST_F(ModbusClientTest, RepeatedTimeoutsOnTcpReconnect) {
  RecordingTap tap;
  client->set_tap(&tap);
  ASSERT_TRUE(client->connect());
  server.inject_timeouts(station::drivers::kTimeoutsBeforeReconnect);
  for (int i = 1; i <= station::drivers::kTimeoutsBeforeReconnect; ++i) {
    auto v = client->read(map.at(cm::kAir));
    ASSERT_FALSE(v);
    EXPECT_EQ(v.error().kind, ErrorKind::timeout) << v.error().message;
    // Connected until the last timeout of the run, then dropped.
    EXPECT_EQ(client->connected(), i < station::drivers::kTimeoutsBeforeReconnect)
        << "after timeout " << i;
    if (i == station::drivers::kTimeoutsBeforeReconnect) {
      EXPECT_NE(v.error().message.find("reconnecting"), std::string::npos) << v.error().message;
    }
  }
  EXPECT_EQ(count_kind(tap.records, "connect"), 1);
  auto again = client->read(map.at(cm::kAir));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_DOUBLE_EQ(again.value(), 25.0);
  EXPECT_EQ(count_kind(tap.records, "connect"), 2);  // a fresh connection served it
  EXPECT_EQ(count_kind(tap.records, "disconnect"), 1);
}

// Only timeouts *in a row* count: an answer in between resets the run.
TEST_F(ModbusClientTest, AnAnswerResetsTheTimeoutRun) {
  RecordingTap tap;
  client->set_tap(&tap);
  ASSERT_TRUE(client->connect());
  server.inject_timeouts(station::drivers::kTimeoutsBeforeReconnect - 1);
  for (int i = 1; i < station::drivers::kTimeoutsBeforeReconnect; ++i)
    ASSERT_FALSE(client->read(map.at(cm::kAir)));
  ASSERT_TRUE(client->read(map.at(cm::kAir)));
  server.inject_timeouts(1);
  ASSERT_FALSE(client->read(map.at(cm::kAir)));
  EXPECT_TRUE(client->connected());
  EXPECT_EQ(count_kind(tap.records, "connect"), 1);
}

// RTU has no connection to renew: repeated timeouts keep the line open and it recovers.
TEST(ModbusClientRtu, RepeatedTimeoutsKeepTheLineOpen) {
  auto map = cm::generic_plc();
  station::sim::ChamberSim sim{map};
  station::sim::ModbusServer server{sim};
  server.start_rtu_pty();
  mb::ModbusClient rtu("chamber-rtu", mb::parse_endpoint(server.endpoint()), 0.2);
  ASSERT_TRUE(rtu.connect()) << server.endpoint();
  server.inject_timeouts(station::drivers::kTimeoutsBeforeReconnect);
  for (int i = 0; i < station::drivers::kTimeoutsBeforeReconnect; ++i) {
    auto v = rtu.read(map.at(cm::kAir));
    ASSERT_FALSE(v);
    EXPECT_EQ(v.error().kind, ErrorKind::timeout) << v.error().message;
  }
  EXPECT_TRUE(rtu.connected());
  auto again = rtu.read(map.at(cm::kAir));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_DOUBLE_EQ(again.value(), 25.0);
}
