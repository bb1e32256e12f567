// simrig's fault commands (sim_devices/fault_commands.hpp) on an in-process SimWorld, each seen
// through the real transports: the station's Modbus drivers over TCP, can_frames over the
// socketpair CAN bus, and the simulated GPIO lines.
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/counters/counter_frames.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/generic_plc/modbus_turntable.hpp"
#include "sim_devices/fault_commands.hpp"
#include "sim_devices/sim_world.hpp"

namespace dr = station::drivers;
namespace mb = station::drivers::modbus;
namespace wire = station::drivers::counters;
namespace sim = station::sim;

namespace {

sim::SimWorldConfig two_gyros() {
  sim::SimWorldConfig c;
  c.gyros = 2;
  c.seed = 3;
  return c;
}

// A world with the station's own Modbus drivers on it and the station end of its CAN bus.
struct Rig {
  sim::SimWorld world{two_gyros()};
  dr::ModbusChamber chamber{"chamber", mb::parse_endpoint(world.chamber_endpoint()),
                            dr::chamber_map::generic_plc(), 0.2};
  dr::ModbusTurntable table{"table", mb::parse_endpoint(world.turntable_endpoint()),
                            dr::turntable_map::generic_plc(), dr::TurntableLimits{}, 0.2};
  int can_fd = std::stoi(world.can_transport().substr(3));  // "fd:N"
  std::uint8_t seq = 0;

  void ok(const std::string& command) {
    EXPECT_EQ(sim::run_fault_command(world, command).substr(0, 2), "ok") << command;
  }
  dr::ChamberState chamber_state() {
    auto s = chamber.read();
    EXPECT_TRUE(s) << s.error().message;
    return s ? s.value() : dr::ChamberState{};
  }

  // One record from the bus (a can_frame, or fewer bytes when corrupted); fails after 5 s.
  std::vector<std::uint8_t> receive() {
    pollfd p{can_fd, POLLIN, 0};
    if (poll(&p, 1, 5000) != 1) {
      ADD_FAILURE() << "no CAN record within 5 s";
      return {};
    }
    std::vector<std::uint8_t> rec(sizeof(can_frame));
    const ssize_t n = recv(can_fd, rec.data(), rec.size(), 0);
    rec.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return rec;
  }
  void sync() {
    const can_frame f = wire::encode(wire::SyncFrame{++seq});
    ASSERT_EQ(send(can_fd, &f, sizeof f, 0), static_cast<ssize_t>(sizeof f));
  }
  // The records answering one SYNC sent after a faulted one: a clean SYNC follows it, and
  // everything before its first STATUS is the faulted burst (bursts leave the bus in order).
  std::vector<can_frame> burst_then_clean(std::size_t clean_records) {
    sync();
    sync();
    const std::uint8_t clean_seq = seq;
    std::vector<can_frame> burst;
    for (;;) {
      const auto rec = receive();
      if (rec.empty()) return burst;
      can_frame f{};
      std::memcpy(&f, rec.data(), rec.size());
      if (rec.size() != sizeof f) f.can_dlc = 0xFF;  // a short record: mark it undecodable
      const auto st = wire::decode_status(f);
      if (st && st.value().latch_seq == clean_seq) break;
      burst.push_back(f);
    }
    for (std::size_t i = 1; i < clean_records; ++i) receive();
    return burst;
  }
};

// Frames a healthy board sends per SYNC: STATUS, COUNTS, TEMPS, DISCHARGE.
constexpr std::size_t kPerBoard = 4;

std::size_t decodable(const std::vector<can_frame>& frames) {
  std::size_t n = 0;
  for (const auto& f : frames) {
    std::uint8_t node = 0;
    const auto kind = wire::classify(f, &node);
    if (!kind) continue;
    switch (kind.value()) {
      case wire::FrameKind::sync:
        break;
      case wire::FrameKind::status:
        n += wire::decode_status(f).ok();
        break;
      case wire::FrameKind::counts:
        n += wire::decode_counts(f).ok();
        break;
      case wire::FrameKind::temps:
        n += wire::decode_temps(f).ok();
        break;
      case wire::FrameKind::discharge:
        n += wire::decode_discharge(f).ok();
        break;
    }
  }
  return n;
}

template <typename T>
std::vector<T> decoded(const std::vector<can_frame>& frames,
                       dr::Result<T> (*decode)(const can_frame&)) {
  std::vector<T> out;
  for (const auto& f : frames) {
    if (auto d = decode(f)) out.push_back(d.value());
  }
  return out;
}

}  // namespace

TEST(SimFaults, DoorAndEstopReachTheChamberTheTableAndTheGpioLines) {
  Rig rig;
  auto gpio = rig.world.gpio_chips();
  rig.ok("door open");
  EXPECT_TRUE(rig.chamber_state().alarms.door_open);
  EXPECT_EQ(gpio->pin_level("DOOR_SW"), false);
  rig.ok("estop press");
  auto t = rig.table.read();
  ASSERT_TRUE(t) << t.error().message;
  EXPECT_TRUE(t.value().interlock_open);
  EXPECT_EQ(gpio->pin_level("ESTOP"), true);
  rig.ok("door close");
  rig.ok("estop release");
  EXPECT_FALSE(rig.chamber_state().alarms.door_open);
  EXPECT_FALSE(rig.table.read().value().interlock_open);
  EXPECT_EQ(gpio->pin_level("DOOR_SW"), true);
  EXPECT_EQ(gpio->pin_level("ESTOP"), false);
}

// The model publishes its registers before every reply; an injected alarm is model state, so it
// survives any number of steps and any write to the alarm register, until it is cleared.
TEST(SimFaults, InjectedChamberAlarmsStayUntilCleared) {
  Rig rig;
  rig.ok("chamber alarm high-limit on");
  rig.ok("chamber alarm sensor on");
  modbus_t* raw = modbus_new_tcp(
      "127.0.0.1", dynamic_cast<station::sim::ModbusServer&>(rig.world.chamber_server()).port());
  ASSERT_EQ(modbus_connect(raw), 0);
  for (int minute = 1; minute <= 10; ++minute) {
    rig.world.advance_to(60.0 * minute);
    EXPECT_EQ(modbus_write_register(raw, 110, 0), -1);  // the alarm register is read-only
    EXPECT_EQ(errno, EMBXILADD);
    const auto s = rig.chamber_state();
    EXPECT_TRUE(s.alarms.high_limit_trip) << "minute " << minute;
    EXPECT_TRUE(s.alarms.sensor_break) << "minute " << minute;
    EXPECT_TRUE(std::isnan(s.air_c));
  }
  modbus_close(raw);
  modbus_free(raw);
  rig.ok("chamber alarm high-limit off");
  rig.ok("chamber alarm sensor off");
  const auto s = rig.chamber_state();
  EXPECT_FALSE(s.alarms.high_limit_trip);
  EXPECT_FALSE(s.alarms.sensor_break);
  EXPECT_DOUBLE_EQ(s.air_c, 25.0);  // output was off at ambient 25 C: the air stayed there
}

TEST(SimFaults, SetpointWrittenFromOutsideIsWhatTheChamberReports) {
  Rig rig;
  EXPECT_EQ(sim::run_fault_command(rig.world, "chamber setpoint 150"), "ok setpoint_c=150.0");
  EXPECT_DOUBLE_EQ(rig.chamber_state().setpoint_c, 150.0);
  EXPECT_EQ(sim::run_fault_command(rig.world, "chamber setpoint 1e300").substr(0, 6), "error:");
}

TEST(SimFaults, ModbusStallAndExceptionUntilCleared) {
  Rig rig;
  rig.ok("chamber stall 3600");
  auto r = rig.chamber.read();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, dr::ErrorKind::timeout);
  rig.ok("chamber stall 0");
  rig.chamber_state();
  rig.ok("table exception 4 2");
  for (int i = 0; i < 2; ++i) {
    auto t = rig.table.read();
    ASSERT_FALSE(t);
    EXPECT_EQ(t.error().kind, dr::ErrorKind::exception);
  }
  EXPECT_TRUE(rig.table.read());
  rig.ok("chamber exception 6 always");
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(rig.chamber.read());
  rig.ok("chamber clear");
  rig.chamber_state();
}

TEST(SimFaults, ModbusDisconnectClosesTheLinkAndRefusesUntilCleared) {
  Rig rig;
  rig.chamber_state();  // connected
  rig.ok("chamber disconnect 3600");
  // The server drops the link on its next poll (<= 100 ms): a bounded wait, not a timing check.
  dr::Result<dr::ChamberState> r = rig.chamber.read();
  for (int i = 0; i < 50 && r; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    r = rig.chamber.read();
  }
  ASSERT_FALSE(r);
  for (int i = 0; i < 3; ++i) {
    auto again = rig.chamber.read();
    ASSERT_FALSE(again);
    EXPECT_EQ(again.error().kind, dr::ErrorKind::disconnected) << again.error().message;
  }
  rig.ok("chamber clear");
  // It listens again on its next poll; the client reconnects on its next call.
  for (int i = 0; i < 50 && !r; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    r = rig.chamber.read();
  }
  EXPECT_TRUE(r) << r.error().message;
}

TEST(SimFaults, CanDropDuplicateAndCorruptTheNextFrames) {
  Rig rig;
  constexpr std::size_t kHealthy = 2 * kPerBoard;
  EXPECT_EQ(decodable(rig.burst_then_clean(kHealthy)), kHealthy);
  rig.ok("can drop 3");
  EXPECT_EQ(rig.burst_then_clean(kHealthy).size(), kHealthy - 3);
  rig.ok("can duplicate 2");
  EXPECT_EQ(rig.burst_then_clean(kHealthy).size(), kHealthy + 2);
  rig.ok("can corrupt 1");
  const auto corrupt = rig.burst_then_clean(kHealthy);
  EXPECT_EQ(corrupt.size(), kHealthy);
  EXPECT_EQ(decodable(corrupt), kHealthy - 1);
}

TEST(SimFaults, CanFaultRatesStayUntilCleared) {
  Rig rig;
  constexpr std::size_t kHealthy = 2 * kPerBoard;
  rig.ok("can duplicate rate 1");
  for (int i = 0; i < 3; ++i) {
    rig.sync();
    for (std::size_t k = 0; k < 2 * kHealthy; ++k) rig.receive();
  }
  rig.ok("can clear");
  EXPECT_EQ(rig.burst_then_clean(kHealthy).size(), kHealthy);
  rig.ok("can corrupt rate 1");
  rig.sync();
  std::vector<can_frame> burst;
  for (std::size_t k = 0; k < kHealthy; ++k) {
    const auto rec = rig.receive();
    can_frame f{};
    std::memcpy(&f, rec.data(), std::min(rec.size(), sizeof f));
    if (rec.size() != sizeof f) f.can_dlc = 0xFF;
    burst.push_back(f);
  }
  EXPECT_EQ(decodable(burst), 0u);
  EXPECT_EQ(sim::run_fault_command(rig.world, "can drop rate 1.5").substr(0, 6), "error:");
}

TEST(SimFaults, BoardResetRestartsCountersAndClockAndFlagsIt) {
  Rig rig;
  rig.world.advance_to(10.0);
  const auto before = rig.burst_then_clean(2 * kPerBoard);
  const auto counts_before = decoded(before, &wire::decode_counts);
  ASSERT_EQ(counts_before.size(), 2u);
  EXPECT_GT(counts_before[0].up, 100000u);  // 10 s of dither at 2e4 pulses/s
  rig.ok("board 1 reset");
  const auto after = rig.burst_then_clean(2 * kPerBoard);
  const auto counts = decoded(after, &wire::decode_counts);
  const auto status = decoded(after, &wire::decode_status);
  ASSERT_EQ(counts.size(), 2u);
  ASSERT_EQ(status.size(), 2u);
  EXPECT_EQ(counts[0].node, 1);
  EXPECT_EQ(counts[0].up, 0u);  // no simulated time since the reset
  EXPECT_EQ(counts[0].down, 0u);
  EXPECT_EQ(status[0].board_time_us, 0u);
  EXPECT_TRUE(status[0].flags & wire::kFlagCounterReset);
  EXPECT_EQ(counts[1].up, counts_before[1].up);  // board 2 untouched
  EXPECT_FALSE(status[1].flags & wire::kFlagCounterReset);
  // The flag is reported once; the clean burst after this one has it clear.
  rig.world.advance_to(11.0);
  const auto later = decoded(rig.burst_then_clean(2 * kPerBoard), &wire::decode_status);
  ASSERT_EQ(later.size(), 2u);
  EXPECT_FALSE(later[0].flags & wire::kFlagCounterReset);
  EXPECT_EQ(later[0].board_time_us, 1000000u);
}

TEST(SimFaults, GyroTemperatureSensorFailureAndASilentBoard) {
  Rig rig;
  rig.ok("gyro 2 temp 1 fail");
  auto burst = rig.burst_then_clean(2 * kPerBoard);
  auto temps = decoded(burst, &wire::decode_temps);
  ASSERT_EQ(temps.size(), 2u);
  EXPECT_EQ(temps[1].centi_c[1], INT16_MIN);  // the sensor's "no value" sentinel
  EXPECT_NE(temps[0].centi_c[1], INT16_MIN);
  EXPECT_TRUE(decoded(burst, &wire::decode_status)[1].flags & wire::kFlagTempSensorFault);
  rig.ok("gyro 2 temp 1 ok");
  rig.ok("board 1 silent");
  // The clean SYNC after the burst is answered by board 2 alone now: 4 records.
  burst = rig.burst_then_clean(kPerBoard);
  ASSERT_EQ(burst.size(), kPerBoard);
  EXPECT_EQ(decoded(burst, &wire::decode_status)[0].node, 2);
  EXPECT_NE(decoded(burst, &wire::decode_temps)[0].centi_c[1], INT16_MIN);
}

TEST(SimFaults, BadCommandsAreOneLineErrorsAndClearEndsEverything) {
  Rig rig;
  for (const char* bad : {"", "door ajar", "board 9 reset", "gyro 1 temp 3 fail",
                          "chamber exception 0", "table stall -1", "can drop many", "fly away"}) {
    const std::string reply = sim::run_fault_command(rig.world, bad);
    EXPECT_EQ(reply.substr(0, 7), "error: ") << bad;
    EXPECT_EQ(reply.find('\n'), std::string::npos) << bad;
  }
  rig.ok("door open");
  rig.ok("estop press");
  rig.ok("chamber alarm high-limit on");
  rig.ok("chamber exception 4 always");
  rig.ok("can corrupt rate 0.5");
  rig.ok("clear");
  const auto s = rig.chamber_state();
  EXPECT_FALSE(s.alarms.any());
  EXPECT_FALSE(rig.table.read().value().interlock_open);
  const std::string status = sim::run_fault_command(rig.world, "status");
  EXPECT_NE(status.find("door=closed estop=released chamber_alarms=0x0 "), std::string::npos)
      << status;
  EXPECT_NE(status.find("can_rates=drop:0,duplicate:0,corrupt:0"), std::string::npos) << status;
  EXPECT_TRUE(rig.chamber.read());
}

// A drop rate loses a binomial share of the frames: 100 SYNCs x 2 boards x 4 frames at p = 0.25
// drop 200 +- 12.2 (sd = sqrt(800 p (1 - p))); 5 sd is the bound. Serviced by hand: no thread.
TEST(SimFaults, CanDropRateLosesABinomialShareOfFrames) {
  int sv[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
  sim::CounterBoardBus bus(sv[1]);
  for (std::uint8_t node : {1, 2}) {
    sim::BoardConfig b;
    b.node = node;
    bus.add_board(b);
  }
  bus.set_fault_rates({0.25, 0, 0}, 11);
  int received = 0;
  for (int i = 0; i < 100; ++i) {
    const can_frame f = wire::encode(wire::SyncFrame{static_cast<std::uint8_t>(i)});
    ASSERT_EQ(send(sv[0], &f, sizeof f, 0), static_cast<ssize_t>(sizeof f));
    ASSERT_EQ(bus.service(std::chrono::milliseconds(1000)), 1);
    can_frame r;
    while (recv(sv[0], &r, sizeof r, MSG_DONTWAIT) > 0) ++received;
  }
  close(sv[0]);
  const int dropped = 800 - received;
  EXPECT_NEAR(dropped, 200, 5 * 12.25);
  EXPECT_GT(dropped, 0);
}
