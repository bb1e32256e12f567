// Issue 37: `modbus_pipeline` against the simulator's Modbus server (it answers a batch of
// requests read at once, faults and all, as it answers them one by one) and in the registry
// (only a Modbus TCP unit takes it). The wire's side against a scripted peer:
// test_modbus_pipeline.cpp.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/modbus/modbus_client.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "drivers/registry/dialects.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace {

namespace dr = station::drivers;
namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;

constexpr double kTimeoutS = 0.3;
constexpr int kPipeline = 8;

struct RecordingTap : dr::Tap {
  std::vector<dr::TapRecord> records;
  void on_exchange(const dr::TapRecord& r) noexcept override { records.push_back(r); }
};

std::unique_ptr<mb::ModbusClient> client_for(const std::string& endpoint, int pipeline,
                                             dr::Tap* tap = nullptr) {
  auto c = std::make_unique<mb::ModbusClient>("chamber", mb::parse_endpoint(endpoint), kTimeoutS);
  c->set_pipeline(pipeline);
  c->set_tap(tap);
  return c;
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

// The simulator's generic PLC chamber served on loopback, read by the chamber's seven points.
struct SimRig {
  SimRig() { server.start_tcp(); }
  mb::RegisterMap map = cm::generic_plc();
  station::sim::ChamberSim sim{map};
  station::sim::ModbusServer server{sim};
  std::vector<mb::Point> points = [this] {
    std::vector<mb::Point> p;
    for (const char* n :
         {cm::kAlarms, cm::kAir, cm::kSetpoint, cm::kStatus, cm::kProduct, cm::kRamp, cm::kRun})
      p.push_back(map.at(n));
    return p;
  }();
  std::vector<mb::ReadBlock> plan = mb::plan_reads(points, 0);
};

}  // namespace

// The simulator's server answers a batch (several requests in one read) as it answers them one
// by one: the same values and tap records as a client reading one at a time, each request counted.
TEST(ModbusPipeline, TheSimulatorAnswersABatchAsItAnswersOneAtATime) {
  SimRig rig;
  ASSERT_GE(rig.plan.size(), 5u);
  RecordingTap taps[2];
  std::vector<double> values[2];
  for (int mode = 0; mode < 2; ++mode) {
    auto client = client_for(rig.server.endpoint(), mode == 0 ? 1 : kPipeline, &taps[mode]);
    const auto v = client->read_points(rig.points, rig.plan);
    ASSERT_TRUE(v) << v.error().message;
    values[mode] = v.value();
  }
  EXPECT_EQ(values[1], values[0]);
  EXPECT_DOUBLE_EQ(values[1][1], 25.0);  // air at the simulator's start
  EXPECT_EQ(seen(taps[1]), seen(taps[0]));
  EXPECT_EQ(rig.server.requests(), 2 * rig.plan.size());
}

// The simulator's own faults within a batch: a request left unanswered is a timeout of that
// request; a dropped connection is a lost link that the next read reopens; dripping replies
// still come whole and in order; a smaller pipeline than the plan reads it in several batches.
TEST(ModbusPipeline, TheSimulatorsFaultsWithinABatch) {
  SimRig rig;
  auto client = client_for(rig.server.endpoint(), kPipeline);
  ASSERT_TRUE(client->read_points(rig.points, rig.plan));
  rig.server.inject_timeouts(1);
  auto v = client->read_points(rig.points, rig.plan);
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().kind, dr::ErrorKind::timeout) << v.error().message;
  EXPECT_NE(v.error().message.find("addr=100 "), std::string::npos) << v.error().message;
  v = client->read_points(rig.points, rig.plan);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_DOUBLE_EQ(v.value()[1], 25.0);

  rig.server.inject_drop(1);
  v = client->read_points(rig.points, rig.plan);
  ASSERT_FALSE(v);
  EXPECT_EQ(v.error().kind, dr::ErrorKind::disconnected) << v.error().message;
  v = client->read_points(rig.points, rig.plan);
  ASSERT_TRUE(v) << v.error().message;

  rig.server.drip_for(60, 0.0005);
  v = client->read_points(rig.points, rig.plan);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_DOUBLE_EQ(v.value()[1], 25.0);
  rig.server.clear_faults();

  client->set_pipeline(2);
  v = client->read_points(rig.points, rig.plan);
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_DOUBLE_EQ(v.value()[1], 25.0);
}

// The option is a Modbus TCP one: a serial line, a gateway in front of one, a request gap and an
// ASCII dialect refuse it by name; a TCP unit takes it and its driver's client has it.
TEST(ModbusPipeline, OnlyAModbusTcpUnitTakesIt) {
  const auto& plc = dr::chamber_dialect("generic_plc");
  dr::DeviceSpec spec;
  spec.name = "chamber";
  spec.model = "generic_plc";
  spec.endpoint = "tcp://127.0.0.1:1502";
  spec.modbus_pipeline = 4;
  EXPECT_NO_THROW(dr::validate(plc, spec));
  const auto refused = [](const auto& dialect, const dr::DeviceSpec& s) {
    try {
      dr::validate(dialect, s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  auto rtu = spec;
  rtu.endpoint = "rtu:/dev/ttyUSB0?baud=19200";
  EXPECT_EQ(refused(plc, rtu).rfind("modbus_pipeline 4: a serial line", 0), 0u)
      << refused(plc, rtu);
  auto gateway = spec;
  gateway.gateway = true;
  EXPECT_EQ(refused(plc, gateway).rfind("modbus_pipeline 4: the serial line behind", 0), 0u)
      << refused(plc, gateway);
  auto gap = spec;
  gap.request_gap_s = 0.03;
  EXPECT_EQ(refused(plc, gap).rfind("modbus_pipeline:", 0), 0u) << refused(plc, gap);
  auto ascii = spec;
  ascii.model = "espec_p300";
  ascii.endpoint = "serial:/dev/ttyUSB0?baud=9600";
  EXPECT_EQ(refused(dr::chamber_dialect("espec_p300"), ascii).rfind("modbus_pipeline:", 0), 0u)
      << refused(dr::chamber_dialect("espec_p300"), ascii);
}

// The registry hands the option to the generic chamber's client; the chamber's reading and its
// command (the two setpoint limits read together, then the write) leave the same tap records as
// one request at a time, and the simulated chamber takes the setpoint either way.
TEST(ModbusPipeline, TheChamberDriverReadsAndCommandsTheSameWithAPipeline) {
  const auto& plc = dr::chamber_dialect("generic_plc");
  std::vector<std::string> records[2];
  for (int mode = 0; mode < 2; ++mode) {
    SimRig rig;
    dr::DeviceSpec spec;
    spec.name = "chamber";
    spec.model = "generic_plc";
    spec.endpoint = rig.server.endpoint();
    spec.modbus_pipeline = mode == 0 ? 1 : kPipeline;
    dr::validate(plc, spec);
    RecordingTap tap;
    dr::LinkOptions options;
    options.tap = &tap;
    auto chamber = plc.make(spec, options);
    auto* modbus = dynamic_cast<dr::ModbusChamber*>(chamber.get());
    ASSERT_NE(modbus, nullptr);
    EXPECT_EQ(modbus->client().pipeline(), spec.modbus_pipeline);
    ASSERT_TRUE(chamber->connect());
    const auto state = chamber->read();
    ASSERT_TRUE(state) << state.error().message;
    EXPECT_DOUBLE_EQ(state.value().air_c, 25.0);
    dr::ChamberCommand c;
    c.setpoint_c = 40.0;
    ASSERT_TRUE(chamber->command(c));
    c.setpoint_c = 1000.0;  // beyond the simulated chamber's limits: refused, nothing written
    const auto refused = chamber->command(c);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().kind, dr::ErrorKind::range) << refused.error().message;
    EXPECT_DOUBLE_EQ(rig.sim.setpoint_c(), 40.0);
    records[mode] = seen(tap);
  }
  EXPECT_EQ(records[1], records[0]);
}
