// Issue 34, point 1: a Modbus reply that drips (one byte every 0.3 s, under libmodbus's 0.5 s
// byte timeout) is a timeout by the exchange's one deadline, never a reply read seconds late; the
// rest of it is dropped, never read as the next reply. Each driver against its simulator face over
// real loopback TCP or RTU on a pty, the drip served by the simulator (`drip` fault).
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/chamber/watlow_f4t/f4t_map.hpp"
#include "drivers/chamber/watlow_f4t/watlow_f4t_chamber.hpp"
#include "drivers/common/stale_link.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/modbus/modbus_frame.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/generic_plc/modbus_turntable.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/faces/watlow_faces.hpp"
#include "sim_devices/fault_commands.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "sim_devices/sim_world.hpp"

namespace {

namespace dr = station::drivers;
namespace sim = station::sim;

constexpr double kTimeoutS = 0.5;  // the station's default (drivers/registry/dialects.cpp)
constexpr double kDripS = 0.3;     // the proxy: under libmodbus's 0.5 s byte timeout
// Reads after a drip ends before one answers: the late bytes are waited for within each read's
// deadline, and a connection reopens after kTimeoutsBeforeReconnect timeouts in a row.
constexpr int kReadsToRecover = dr::kTimeoutsBeforeReconnect + 1;

// Seconds `f` took. Only an upper bound with a wide margin is ever asserted on it: a dripped
// reply of n bytes took n * 0.3 s (3 s and more) before the fix.
template <typename F>
double seconds_of(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
// The deadline of one exchange with room for a loaded machine; far under any dripped reply.
constexpr double kOneExchangeBoundS = 3 * kTimeoutS;

struct F4tRig {
  F4tRig() : face(chamber, sim::WatlowPanel{}), server(face, 1) {
    server.start_tcp(0);
    driver = std::make_unique<dr::WatlowF4tChamber>(
        "chamber", dr::modbus::parse_endpoint(server.endpoint()),
        dr::watlow_f4t::map(1, sim::WatlowPanel{}.run_event, false, 1, 2, 2), kTimeoutS);
  }
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::F4tFace face;
  sim::ModbusServer server;
  std::unique_ptr<dr::WatlowF4tChamber> driver;
};

}  // namespace

// An F4T whose reply drips: the read is one exchange that ends in a timeout by its deadline; once
// the drip ends the driver reads the right air again (nothing misframed on the way).
TEST(ModbusDrip, F4tChamberReplyThatDripsIsATimeout) {
  F4tRig rig;
  auto first = rig.driver->read();
  ASSERT_TRUE(first) << first.error().message;
  const auto before = rig.server.requests();
  rig.server.drip_for(3600, kDripS);
  dr::Result<dr::ChamberState> dripped = dr::make_error(dr::ErrorKind::io, "not read");
  const double took_s = seconds_of([&] { dripped = rig.driver->read(); });
  ASSERT_FALSE(dripped) << "a dripped reply was read as an answer";
  EXPECT_EQ(dripped.error().kind, dr::ErrorKind::timeout) << dripped.error().message;
  EXPECT_EQ(rig.server.requests() - before, 1u);  // one exchange; the driver stops at its failure
  EXPECT_LT(took_s, kOneExchangeBoundS);
  rig.server.drip_for(0, 0);
  for (int i = 0; i < kReadsToRecover; ++i) {
    auto s = rig.driver->read();
    if (!s) continue;
    EXPECT_NEAR(s.value().air_c, rig.chamber.air_c(), 0.05) << "read " << i;
    return;
  }
  FAIL() << "no answer in " << kReadsToRecover << " reads after the drip ended";
}

// A generic_plc table dripping through simrig's fault command: its interlock read is a timeout,
// never a reading seconds old; the next reads are timeouts too while the late bytes arrive, then
// the table answers with its own angle.
TEST(ModbusDrip, GenericTableReplyThatDripsIsATimeout) {
  sim::SimWorldConfig wc;
  wc.gyros = 1;
  sim::SimWorld world(wc);
  dr::ModbusTurntable table("table", dr::modbus::parse_endpoint(world.turntable_endpoint()),
                            dr::turntable_map::generic_plc(), dr::TurntableLimits{}, kTimeoutS);
  ASSERT_TRUE(table.read());
  const auto before = world.turntable_server().requests();
  ASSERT_EQ(sim::run_fault_command(world, "table drip 3600"), "ok");
  dr::Result<dr::TurntableState> dripped = dr::make_error(dr::ErrorKind::io, "not read");
  const double took_s = seconds_of([&] { dripped = table.read(); });
  ASSERT_FALSE(dripped) << "a dripped reply was read as an answer";
  EXPECT_EQ(dripped.error().kind, dr::ErrorKind::timeout) << dripped.error().message;
  EXPECT_EQ(world.turntable_server().requests() - before, 1u);
  EXPECT_LT(took_s, kOneExchangeBoundS);
  EXPECT_NE(dripped.error().message.find("too slowly"), std::string::npos)
      << dripped.error().message;
  // Still dripping, over the reconnect the stale-link rule makes: timeouts that say the reply
  // came too slowly, never that the unit id is wrong (the unit did answer, byte by byte).
  for (int i = 0; i < dr::kTimeoutsBeforeReconnect; ++i) {
    auto again = table.read();
    ASSERT_FALSE(again) << "read " << i;
    EXPECT_EQ(again.error().kind, dr::ErrorKind::timeout) << again.error().message;
    EXPECT_EQ(again.error().message.find("unit_id"), std::string::npos) << again.error().message;
  }
  ASSERT_EQ(sim::run_fault_command(world, "table drip 0"), "ok");
  for (int i = 0; i < kReadsToRecover; ++i) {
    auto s = table.read();
    if (!s) continue;
    EXPECT_NEAR(s.value().angle_deg, world.turntable().angle_deg(), 0.01) << "read " << i;
    return;
  }
  FAIL() << "no answer in " << kReadsToRecover << " reads after the drip ended";
}

// RTU on a pty: no connection to renew, so the late bytes are framed (by function code and byte
// count) and dropped as they come; every read is a timeout or the right value, never a value
// taken from the dripped reply's tail.
TEST(ModbusDrip, RtuReplyThatDripsIsATimeoutAndNeverMisframed) {
  const auto map = dr::chamber_map::generic_plc(7);
  sim::ChamberSim chamber(map);
  sim::ModbusServer server(chamber, 7);
  server.start_rtu_pty(19200);
  dr::ModbusChamber driver("chamber-rtu", dr::modbus::parse_endpoint(server.endpoint()), map,
                           kTimeoutS);
  ASSERT_TRUE(driver.command({.setpoint_c = 40.0, .ramp_c_per_min = 0.0}));
  auto first = driver.read();
  ASSERT_TRUE(first) << first.error().message;
  const double drip_s = 0.1;  // under the byte timeout too; the reply's tail drains sooner
  server.drip_for(3600, drip_s);
  dr::Result<dr::ChamberState> dripped = dr::make_error(dr::ErrorKind::io, "not read");
  const double took_s = seconds_of([&] { dripped = driver.read(); });
  ASSERT_FALSE(dripped) << "a dripped reply was read as an answer";
  EXPECT_EQ(dripped.error().kind, dr::ErrorKind::timeout) << dripped.error().message;
  EXPECT_LT(took_s, kOneExchangeBoundS);
  server.drip_for(0, 0);
  // The tail of one dripped reply (at most 256 bytes on RTU) drains in 256 * drip_s at most.
  const int reads = static_cast<int>(std::ceil(256 * drip_s / kTimeoutS)) + 2;
  for (int i = 0; i < reads; ++i) {
    auto s = driver.read();
    if (!s) {
      EXPECT_EQ(s.error().kind, dr::ErrorKind::timeout) << s.error().message;
      continue;
    }
    EXPECT_DOUBLE_EQ(s.value().setpoint_c, 40.0) << "read " << i;
    EXPECT_NEAR(s.value().air_c, chamber.air_c(), 0.05) << "read " << i;
    return;
  }
  FAIL() << "no answer in " << reads << " reads after the drip ended";
}

// The framing the client reads replies by (modbus_frame.hpp), against frames written out by hand
// from the Modbus documents: a reply's length from its first bytes, and libmodbus's checks.
TEST(ModbusFrame, ReplyLengthsFromTheirFirstBytes) {
  namespace mb = dr::modbus;
  using B = std::vector<std::uint8_t>;
  // TCP: MBAP length 7 (unit, fc 3, byte count 4, 4 data bytes) -> 6 + 7 bytes in all.
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::tcp, B{0, 1, 0, 0, 0}), 0);
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::tcp, B{0, 1, 0, 0, 0, 7}), 13);
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::tcp, B{0, 1, 0, 5, 0, 7}), -1);     // protocol id
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::tcp, B{0, 1, 0, 0, 0xFF, 0}), -1);  // > 260
  // RTU: read -> unit, fc, count, data, CRC; write 6/16 -> 8; exception -> 5; unknown fc -> -1.
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::rtu, B{7, 3}), 0);
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::rtu, B{7, 3, 4}), 9);
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::rtu, B{7, 16}), 8);
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::rtu, B{7, 6}), 8);
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::rtu, B{7, 0x83}), 5);
  EXPECT_EQ(mb::reply_frame_length(mb::Framing::rtu, B{7, 0x42}), -1);
}

TEST(ModbusFrame, RepliesCheckedAsLibmodbusDoes) {
  namespace mb = dr::modbus;
  using B = std::vector<std::uint8_t>;
  const B read2{7, 3, 0x00, 0x64, 0x00, 0x02};  // unit 7: read 2 holding registers at 100
  const auto tcp_req = mb::request_frame(mb::Framing::tcp, 0x1234, read2);
  EXPECT_EQ(tcp_req, (B{0x12, 0x34, 0, 0, 0, 6, 7, 3, 0, 0x64, 0, 2}));
  const B ok{0x12, 0x34, 0, 0, 0, 7, 7, 3, 4, 0x41, 0xC8, 0, 0};
  EXPECT_EQ(mb::check_reply(mb::Framing::tcp, tcp_req, ok), 0);
  B other_tid = ok;
  other_tid[1] = 0x35;
  EXPECT_EQ(mb::check_reply(mb::Framing::tcp, tcp_req, other_tid), EMBBADDATA);
  const B short_count{0x12, 0x34, 0, 0, 0, 5, 7, 3, 2, 0x41, 0xC8};
  EXPECT_EQ(mb::check_reply(mb::Framing::tcp, tcp_req, short_count), EMBBADDATA);
  const B busy{0x12, 0x34, 0, 0, 0, 3, 7, 0x83, 6};
  EXPECT_EQ(mb::check_reply(mb::Framing::tcp, tcp_req, busy), EMBXSBUSY);
  const B wrong_fc_exception{0x12, 0x34, 0, 0, 0, 3, 7, 0x84, 6};
  EXPECT_EQ(mb::check_reply(mb::Framing::tcp, tcp_req, wrong_fc_exception), EMBBADEXC);
  // RTU: the CRC of "01 03 00 00 00 01" is 84 0A (low byte first), as every Modbus primer shows.
  EXPECT_EQ(mb::request_frame(mb::Framing::rtu, 0, B{1, 3, 0, 0, 0, 1}),
            (B{1, 3, 0, 0, 0, 1, 0x84, 0x0A}));
  const auto rtu_req = mb::request_frame(mb::Framing::rtu, 0, read2);
  auto rtu_reply = [](B body) {
    const auto crc = mb::crc16(body);
    body.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    body.push_back(static_cast<std::uint8_t>(crc >> 8));
    return body;
  };
  EXPECT_EQ(mb::check_reply(mb::Framing::rtu, rtu_req, rtu_reply({7, 3, 4, 1, 2, 3, 4})), 0);
  EXPECT_EQ(mb::check_reply(mb::Framing::rtu, rtu_req, rtu_reply({8, 3, 4, 1, 2, 3, 4})),
            EMBBADSLAVE);
  auto bad_crc = rtu_reply({7, 3, 4, 1, 2, 3, 4});
  bad_crc.back() ^= 0xFF;
  EXPECT_EQ(mb::check_reply(mb::Framing::rtu, rtu_req, bad_crc), EMBBADCRC);
}
