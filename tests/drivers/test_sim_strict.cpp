// The simulated Modbus devices answer bad requests as real ones do, seen by a plain libmodbus
// client over real sockets and a pty: exception 01/02/03, and silence for a foreign RTU unit.
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <cerrno>
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "sim_devices/servers/modbus_strict.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace cm = station::drivers::chamber_map;
namespace ttm = station::drivers::turntable_map;
namespace sim = station::sim;

namespace {

struct FreeCtx {
  void operator()(modbus_t* c) const noexcept {
    modbus_close(c);
    modbus_free(c);
  }
};
using Ctx = std::unique_ptr<modbus_t, FreeCtx>;

Ctx tcp_client(int port) {
  Ctx c(modbus_new_tcp("127.0.0.1", port));
  modbus_set_response_timeout(c.get(), 0, 500000);
  EXPECT_EQ(modbus_connect(c.get()), 0) << modbus_strerror(errno);
  return c;
}

// errno of a libmodbus call that must fail, or 0 if it succeeded.
int failure(int rc) {
  return rc == -1 ? errno : 0;
}

struct ChamberRig {
  sim::ChamberSim model{cm::generic_plc()};
  sim::ModbusServer server{model};
  ChamberRig() { server.start_tcp(); }
};

struct TableRig {
  sim::TurntableSim model{ttm::generic_plc()};
  sim::ModbusServer server{model};
  TableRig() { server.start_tcp(); }
};

}  // namespace

// F4: 100 air (ro), 104 product (ro), 110 alarms (ro), 300 setpoint (rw); 101..103 unmapped.
TEST(StrictModbus, ReadBlockOverAnUnmappedRegisterIsIllegalDataAddress) {
  ChamberRig rig;
  auto c = tcp_client(rig.server.port());
  std::uint16_t w[8] = {};
  EXPECT_EQ(failure(modbus_read_registers(c.get(), 100, 5, w)), EMBXILADD);
  EXPECT_EQ(failure(modbus_read_registers(c.get(), 99, 2, w)), EMBXILADD);
  EXPECT_EQ(failure(modbus_read_input_registers(c.get(), 100, 1, w)), EMBXILADD);  // no table 4
  ASSERT_EQ(modbus_read_registers(c.get(), 100, 1, w), 1) << modbus_strerror(errno);
  EXPECT_EQ(w[0], 250);  // 25.0 C in tenths
  ASSERT_EQ(modbus_read_registers(c.get(), 602, 2, w), 2) << modbus_strerror(errno);  // adjacent
}

TEST(StrictModbus, WriteToAReadOnlyOrUnmappedRegisterIsIllegalDataAddressAndChangesNothing) {
  ChamberRig rig;
  rig.model.set_door_open(true);
  auto c = tcp_client(rig.server.port());
  EXPECT_EQ(failure(modbus_write_register(c.get(), 100, 999)), EMBXILADD);  // air
  EXPECT_EQ(failure(modbus_write_register(c.get(), 110, 0)), EMBXILADD);    // alarms
  EXPECT_EQ(failure(modbus_write_register(c.get(), 101, 0)), EMBXILADD);    // unmapped
  const std::uint16_t two[2] = {500, 0};
  EXPECT_EQ(failure(modbus_write_registers(c.get(), 300, 2, two)), EMBXILADD);  // 301 unmapped
  std::uint16_t alarms = 0;
  ASSERT_EQ(modbus_read_registers(c.get(), 110, 1, &alarms), 1);
  EXPECT_EQ(alarms, cm::kDoorOpen);
  EXPECT_DOUBLE_EQ(rig.model.setpoint_c(), 25.0);
  EXPECT_EQ(modbus_write_register(c.get(), 300, 500), 1) << modbus_strerror(errno);
  EXPECT_DOUBLE_EQ(rig.model.setpoint_c(), 50.0);
}

TEST(StrictModbus, AValueTheDeviceRefusesIsIllegalDataValue) {
  ChamberRig chamber;
  auto c = tcp_client(chamber.server.port());
  EXPECT_EQ(failure(modbus_write_register(c.get(), 2000, 2)), EMBXILVAL);      // run is 0/1
  EXPECT_EQ(failure(modbus_write_register(c.get(), 310, 0xFFF6)), EMBXILVAL);  // ramp -1.0
  EXPECT_EQ(modbus_write_register(c.get(), 2000, 0), 1) << modbus_strerror(errno);
  TableRig table;
  auto t = tcp_client(table.server.port());
  EXPECT_EQ(failure(modbus_write_register(t.get(), 0, 5)), EMBXILVAL);  // mode 0..2
  EXPECT_EQ(failure(modbus_write_register(t.get(), 6, 7)), EMBXILVAL);  // lock 0/1
  const std::uint16_t nan_words[2] = {0x7FC0, 0x0000};                  // float32 NaN, ABCD
  EXPECT_EQ(failure(modbus_write_registers(t.get(), 2, 2, nan_words)), EMBXILVAL);
  // Half of the float32 position demand at 2..3 is no value at all.
  EXPECT_EQ(failure(modbus_write_register(t.get(), 3, 0)), EMBXILADD);
}

TEST(StrictModbus, AFunctionTheDeviceDoesNotImplementIsIllegalFunction) {
  ChamberRig rig;
  auto c = tcp_client(rig.server.port());
  std::uint8_t bits[8] = {};
  EXPECT_EQ(failure(modbus_read_bits(c.get(), 0, 1, bits)), EMBXILFUN);
  EXPECT_EQ(failure(modbus_write_bit(c.get(), 0, 1)), EMBXILFUN);
}

TEST(StrictModbus, TurntableInputBlockIsServedWholeButNotPastItsEnd) {
  TableRig rig;
  auto t = tcp_client(rig.server.port());
  std::uint16_t w[8] = {};
  EXPECT_EQ(modbus_read_input_registers(t.get(), 100, 6, w), 6) << modbus_strerror(errno);
  EXPECT_EQ(failure(modbus_read_input_registers(t.get(), 100, 7, w)), EMBXILADD);
  EXPECT_EQ(failure(modbus_read_registers(t.get(), 0, 3, w)), EMBXILADD);  // 1 is unmapped
}

// On a multidrop RTU line a device ignores frames for other units: the master times out.
TEST(StrictModbus, RtuRequestForAForeignUnitGetsNoAnswerAtAll) {
  sim::ChamberSim model{cm::generic_plc()};
  sim::ModbusServer server{model, 1};
  server.start_rtu_pty();
  Ctx c(modbus_new_rtu(server.pty_path().c_str(), 19200, 'N', 8, 1));
  ASSERT_TRUE(c);
  modbus_set_response_timeout(c.get(), 0, 300000);
  ASSERT_EQ(modbus_connect(c.get()), 0) << modbus_strerror(errno);
  std::uint16_t w = 0;
  for (int unit : {2, 247}) {
    modbus_set_slave(c.get(), unit);
    EXPECT_EQ(failure(modbus_read_registers(c.get(), 100, 1, &w)), ETIMEDOUT) << "unit " << unit;
  }
  const std::uint64_t before = server.requests();
  modbus_set_slave(c.get(), 1);
  modbus_flush(c.get());
  ASSERT_EQ(modbus_read_registers(c.get(), 100, 1, &w), 1) << modbus_strerror(errno);
  EXPECT_EQ(w, 250);
  EXPECT_EQ(server.requests(), before + 1);  // the foreign frames were never requests to it
  // Unit 1 still gets its exceptions on RTU (framing and CRC of the exception reply).
  EXPECT_EQ(failure(modbus_read_registers(c.get(), 100, 2, &w)), EMBXILADD);
}

// The decision itself, without transport: a PDU and a map in, an exception code out.
TEST(StrictModbus, RequestExceptionChecksQuantityAndByteCount) {
  const auto map = cm::generic_plc();
  using Pdu = std::vector<std::uint8_t>;
  EXPECT_EQ(sim::request_exception(map, Pdu{0x03, 0x00, 0x64, 0x00, 0x01}), 0);
  EXPECT_EQ(sim::request_exception(map, Pdu{0x03, 0x00, 0x64, 0x00, 0x00}), sim::kIllegalDataValue);
  EXPECT_EQ(sim::request_exception(map, Pdu{0x03, 0x00, 0x64, 0x00, 0x7E}), sim::kIllegalDataValue);
  EXPECT_EQ(sim::request_exception(map, Pdu{0x10, 0x01, 0x2C, 0x00, 0x01, 0x03, 0, 0}),
            sim::kIllegalDataValue);  // byte count 3 for one register
  EXPECT_EQ(sim::request_exception(map, Pdu{0x10, 0x01, 0x2C, 0x00, 0x01, 0x02, 0x01, 0xF4}), 0);
  EXPECT_EQ(sim::request_exception(map, Pdu{0x2B}), sim::kIllegalFunction);
  EXPECT_EQ(sim::request_exception(map, Pdu{0x03, 0x00}), sim::kIllegalDataValue);
  EXPECT_EQ(sim::request_exception(map, Pdu{}), sim::kIllegalFunction);
}
