// Block reads of ModbusChamber::read(): the plan (plan_reads) and the requests the server sees.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;
using station::drivers::ChamberState;
using station::drivers::ErrorKind;
using station::drivers::ModbusChamber;
using station::sim::ChamberSim;
using station::sim::ModbusServer;

namespace {

mb::Point point(const char* name, std::uint16_t addr, int unit = 1,
                mb::FunctionCode fc = mb::FunctionCode::holding,
                mb::PointType type = mb::PointType::uint16) {
  return mb::Point{name, addr, type, 1.0, mb::WordOrder::abcd, fc, unit, false, mb::Access::ro};
}

// Requests one read() makes, and its state, against a fresh simulated chamber.
struct Counted {
  std::uint64_t requests = 0;
  ChamberState state;
};

Counted count_one_read(const mb::RegisterMap& map, int max_gap) {
  ChamberSim sim(map);
  ModbusServer server(sim);
  server.start_tcp();
  ModbusChamber chamber("chamber", mb::parse_endpoint(server.endpoint()), map, 0.5);
  chamber.set_max_read_gap(max_gap);
  sim.step_to(600.0);
  const std::uint64_t before = server.requests();
  auto s = chamber.read();
  EXPECT_TRUE(s) << s.error().message;
  return {server.requests() - before, s ? s.value() : ChamberState{}};
}

}  // namespace

TEST(ReadPlan, MergesNeighboursWithinTheGapOfOneUnitAndTable) {
  const std::vector<mb::Point> pts{
      point("a", 100),
      point("b", 117),  // 16 unused registers (101..116) after a: merged
      point("c", 134),  // 16 after b (118..133): merged
      point("d", 152),  // 17 after c: new block
      point("e", 152, 2),
      point("f", 153, 1, mb::FunctionCode::input),
      point("g", 153, 1, mb::FunctionCode::holding, mb::PointType::float32)};
  const auto blocks = mb::plan_reads(pts, 16);
  ASSERT_EQ(blocks.size(), 4u);
  EXPECT_EQ(blocks[0].start, 100);
  EXPECT_EQ(blocks[0].count, 35);
  EXPECT_EQ(blocks[0].points, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(blocks[1].start, 152);  // d and the float32 g at 153..154
  EXPECT_EQ(blocks[1].count, 3);
  EXPECT_EQ(blocks[1].points, (std::vector<std::size_t>{3, 6}));
  EXPECT_EQ(blocks[2].function, mb::FunctionCode::input);
  EXPECT_EQ(blocks[3].unit_id, 2);
  EXPECT_EQ(mb::plan_reads(pts, 0).size(), 6u);  // only d and g are adjacent
  EXPECT_EQ(mb::plan_reads(pts, -1).size(), pts.size());
}

TEST(ReadPlan, NeverAsksForMoreThan125Registers) {
  std::vector<mb::Point> pts;
  for (std::uint16_t a = 0; a <= 112; a += 16) pts.push_back(point("p", a));  // gaps of 15
  pts.push_back(point("last_in", 124));  // block 0..124 is exactly 125 registers
  pts.push_back(point("next", 125));     // would make 126
  const auto blocks = mb::plan_reads(pts, 16);
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[0].count, mb::kMaxReadRegisters);
  EXPECT_EQ(blocks[0].points.size(), pts.size() - 1);
  EXPECT_EQ(blocks[1].start, 125);
}

// Watlow F4: 100 air, 104 product, 110 alarms | 200 status | 300 setpoint, 310 ramp | 2000 run.
// The simulated F4 is strict like the real one (a block over the unimplemented 101..103 is
// exception 02), so the default plan merges only adjacent points: 7 requests, none refused.
TEST(ModbusChamber, DefaultReadNeverSpansUnmappedRegistersOfAStrictF4) {
  const auto map = cm::generic_plc();
  const Counted block = count_one_read(map, ModbusChamber::kDefaultMaxReadGap);
  const Counted single = count_one_read(map, -1);
  EXPECT_EQ(block.requests, 7u);
  EXPECT_EQ(single.requests, 7u);
  EXPECT_DOUBLE_EQ(block.state.air_c, single.state.air_c);
  EXPECT_DOUBLE_EQ(block.state.product_c, single.state.product_c);
  EXPECT_DOUBLE_EQ(block.state.setpoint_c, single.state.setpoint_c);
  EXPECT_EQ(block.state.mode, single.state.mode);
  EXPECT_EQ(block.state.run_enabled, single.state.run_enabled);
}

// The old default (gap 16) asked for 100..110 in one read: a strict F4 refuses it with 02.
TEST(ModbusChamber, GapBridgingBlockReadIsRefusedByAStrictChamber) {
  const auto map = cm::generic_plc();
  ChamberSim sim(map);
  ModbusServer server(sim);
  server.start_tcp();
  ModbusChamber chamber("chamber", mb::parse_endpoint(server.endpoint()), map, 0.5);
  chamber.set_max_read_gap(16);
  auto s = chamber.read();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().kind, ErrorKind::exception);
  EXPECT_NE(s.error().message.find("Illegal data address"), std::string::npos) << s.error().message;
}

// F4T: no two read points are adjacent (floats at 2800, 2880, 2160, 2168; words elsewhere).
TEST(ModbusChamber, ReadOfF4tFloatPointsSucceedsAgainstAStrictChamber) {
  const auto map = cm::generic_plc_float();
  const Counted block = count_one_read(map, ModbusChamber::kDefaultMaxReadGap);
  EXPECT_EQ(block.requests, 7u);
  EXPECT_DOUBLE_EQ(block.state.air_c, count_one_read(map, -1).state.air_c);
}

TEST(ModbusChamber, FailedBlockReadIsOneTypedErrorAndTheNextReadRecovers) {
  const auto map = cm::generic_plc();
  ChamberSim sim(map);
  ModbusServer server(sim);
  server.start_tcp();
  ModbusChamber chamber("chamber", mb::parse_endpoint(server.endpoint()), map, 0.2);
  server.inject_exception(MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
  auto e = chamber.read();
  ASSERT_FALSE(e);
  EXPECT_EQ(e.error().kind, ErrorKind::exception);
  EXPECT_EQ(server.requests(), 1u);  // gave up at the first failing block
  auto ok = chamber.read();
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_DOUBLE_EQ(ok.value().air_c, 25.0);
}

// Ramp, run, status and product are read back every N reads (drivers/modbus/readback.hpp), and
// on the read after a write or a reconnect; alarms, air and the setpoint on every read.
TEST(ModbusChamber, CommandRegistersAreReadBackEveryNReadsAndAfterAWriteOrReconnect) {
  const auto map = cm::generic_plc();
  ChamberSim sim(map);
  ModbusServer server(sim);
  server.start_tcp();
  ModbusChamber chamber("chamber", mb::parse_endpoint(server.endpoint()), map, 0.5);
  chamber.set_readback_every(5);
  const auto requests_of_read = [&] {
    const std::uint64_t before = server.requests();
    auto s = chamber.read();
    EXPECT_TRUE(s) << s.error().message;
    return server.requests() - before;
  };
  std::vector<std::uint64_t> seen;
  for (int i = 0; i < 11; ++i) seen.push_back(requests_of_read());
  // Full reads are 7 blocks (no two points adjacent), live reads 3 (110, 100, 300).
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{7, 3, 3, 3, 3, 7, 3, 3, 3, 3, 7}));
  // The panel's setpoint shows on the very next read; its ramp only at the next read-back.
  sim.set_setpoint_c(-12.5);
  auto s = chamber.read();
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s.value().setpoint_c, -12.5);
  // A write: the next read confirms what the controller took.
  ASSERT_TRUE(chamber.command({.ramp_c_per_min = 1.5}));
  EXPECT_EQ(requests_of_read(), 7u);
  s = chamber.read();
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s.value().ramp_c_per_min, 1.5);
  // A reconnect (the controller may have restarted): full again.
  EXPECT_EQ(requests_of_read(), 3u);
  server.disconnect_for(0.0);
  // Under load the server's re-listen can lose the first reconnect attempt; the client then
  // backs off 0.5 s (drivers/common/backoff.hpp), so the attempts are spread over up to 5 s of
  // wall time rather than made in one burst that ends inside the back-off.
  std::uint64_t first_after_reconnect = 0;
  for (int i = 0; i < 100 && first_after_reconnect == 0; ++i) {
    const std::uint64_t before = server.requests();
    if (chamber.read()) {
      first_after_reconnect = server.requests() - before;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  EXPECT_EQ(first_after_reconnect, 7u);
  EXPECT_EQ(requests_of_read(), 3u);
}
