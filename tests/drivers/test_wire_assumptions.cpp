// Issue 33 point 6: the wire's other assumptions, over real sockets and a pty against the
// simulator. A unit answers only its own unit id as its link does (silence on a serial line and on
// its own TCP port, exception 0x0B from a gateway) and the driver names the unit id; a Watlow on a
// serial line gets its 30 ms between requests (seen in the simulator's arrival times); an F4T's
// floats read right in either word order when configured, and the other order is refused; an F4T
// behind a TCP-to-RTU gateway reads its serial port's units register.
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/chamber/float_word_order.hpp"
#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/registry/dialects.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/faces/watlow_faces.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace {

namespace dr = station::drivers;
namespace mb = station::drivers::modbus;
namespace sim = station::sim;

struct FreeCtx {
  void operator()(modbus_t* c) const noexcept {
    modbus_close(c);
    modbus_free(c);
  }
};
using Ctx = std::unique_ptr<modbus_t, FreeCtx>;

Ctx connected(modbus_t* c) {
  Ctx ctx(c);
  modbus_set_response_timeout(ctx.get(), 0, 300000);
  EXPECT_EQ(modbus_connect(ctx.get()), 0) << modbus_strerror(errno);
  return ctx;
}

// errno of a libmodbus call that must fail, or 0 if it succeeded.
int failure(int rc) {
  return rc == -1 ? errno : 0;
}

int read_air(modbus_t* c, int unit) {
  std::uint16_t w = 0;
  modbus_set_slave(c, unit);
  return failure(modbus_read_registers(c, 100, 1, &w));
}

// A generic chamber (100 air, 300 setpoint) served as unit 1.
struct PlcRig {
  sim::ChamberSim model{dr::chamber_map::generic_plc()};
  sim::ModbusServer server{model, 1};
};

// An F4T and its driver, built as the configuration builds it (the dialect's row and timing).
struct F4tRig {
  F4tRig(sim::WatlowPanel panel, bool rtu, sim::UnitLink link)
      : face(chamber, panel, panel.modbus_address, rtu), server(face, panel.modbus_address) {
    if (link == sim::UnitLink::rtu)
      server.start_rtu_pty(19200);
    else
      server.start_tcp(0, link);
  }
  std::unique_ptr<dr::Chamber> driver(dr::DeviceSpec spec) const {
    const auto& dialect = dr::chamber_dialect("watlow_f4t");
    spec.name = "chamber";
    spec.model = "watlow_f4t";
    spec.endpoint = server.endpoint();
    dr::validate(dialect, spec);
    spec.request_gap_s = dr::default_request_gap_s(dialect, spec);
    return dialect.make(spec, {});
  }
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::F4tFace face;
  sim::ModbusServer server;
};

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

// Modbus over Serial Line v1.02 2.2: a unit answers its own address only; a broadcast (unit 0)
// write is executed by every unit and answered by none.
TEST(UnitId, OnASerialLineOnlyTheUnitsAddressIsAnsweredAndABroadcastWriteIsExecutedSilently) {
  PlcRig rig;
  rig.server.start_rtu_pty();
  Ctx c = connected(modbus_new_rtu(rig.server.pty_path().c_str(), 19200, 'N', 8, 1));
  for (int unit : {2, 255, 0}) EXPECT_EQ(read_air(c.get(), unit), ETIMEDOUT) << "unit " << unit;
  modbus_set_slave(c.get(), 0);
  (void)modbus_write_register(c.get(), 300, 500);  // libmodbus may or may not wait for a reply
  modbus_flush(c.get());
  EXPECT_DOUBLE_EQ(rig.model.setpoint_c(), 50.0);  // executed
  EXPECT_EQ(read_air(c.get(), 1), 0);              // and nothing left on the line to misread
}

// Implementation Guide v1.0b p. 23: a device addressed by IP takes 0xFF (and 0); another unit
// id is not its own: no answer.
TEST(UnitId, OnItsOwnTcpPortAUnitAnswersItsAddress255And0AndNothingElse) {
  PlcRig rig;
  rig.server.start_tcp();
  Ctx c = connected(modbus_new_tcp("127.0.0.1", rig.server.port()));
  for (int unit : {1, 255, 0}) EXPECT_EQ(read_air(c.get(), unit), 0) << "unit " << unit;
  EXPECT_EQ(read_air(c.get(), 2), ETIMEDOUT);
}

// Application Protocol v1.1b3 section 7: a gateway whose target does not answer replies 0x0B.
TEST(UnitId, AGatewayAnswersExceptionOBForAUnitThatIsNotBehindIt) {
  PlcRig rig;
  rig.server.start_tcp(0, sim::UnitLink::tcp_gateway);
  Ctx c = connected(modbus_new_tcp("127.0.0.1", rig.server.port()));
  EXPECT_EQ(read_air(c.get(), 1), 0);
  EXPECT_EQ(read_air(c.get(), 2), EMBXGTAR);
  EXPECT_EQ(read_air(c.get(), 255), EMBXGTAR);
}

// The driver's side: a wrong unit_id is one bounded failure naming the unit, never a hang.
TEST(UnitId, TheDriverNamesTheUnitIdItAskedWhenNothingAnswers) {
  for (const auto link :
       {sim::UnitLink::rtu, sim::UnitLink::tcp_device, sim::UnitLink::tcp_gateway}) {
    const bool rtu = link == sim::UnitLink::rtu;
    F4tRig rig({}, rtu || link == sim::UnitLink::tcp_gateway, link);
    auto driver = rig.driver({.unit_id = 2, .gateway = link == sim::UnitLink::tcp_gateway});
    auto id = driver->identify();
    ASSERT_FALSE(id) << to_string(link);
    const std::string& m = id.error().message;
    EXPECT_TRUE(has(m, "unit 2")) << m;
    EXPECT_TRUE(has(m, "unit_id")) << m;
    if (link == sim::UnitLink::tcp_gateway) {
      EXPECT_EQ(id.error().kind, dr::ErrorKind::exception) << m;
      EXPECT_TRUE(has(m, "gateway")) << m;
    } else {
      EXPECT_EQ(id.error().kind, dr::ErrorKind::timeout) << m;
    }
    EXPECT_FALSE(driver->read());  // the next call fails the same way, bounded
  }
}

// CCL modbus.py:373-375: 30 ms between requests to a Watlow on a serial line; none on TCP.
TEST(RequestGap, AWatlowOnASerialLineGetsItsPauseBetweenEveryTwoRequests) {
  F4tRig rig({}, true, sim::UnitLink::rtu);
  auto driver = rig.driver({});
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(driver->read());
  const auto t = rig.server.request_arrivals_s();
  ASSERT_GE(t.size(), 10u);
  double smallest_s = 1e9;
  for (std::size_t i = 1; i < t.size(); ++i) {
    EXPECT_GE(t[i] - t[i - 1], 0.030) << "requests " << i - 1 << " and " << i;
    smallest_s = std::min(smallest_s, t[i] - t[i - 1]);
  }
  RecordProperty("smallest_gap_ms", std::to_string(smallest_s * 1e3));
}

TEST(RequestGap, TheDialectsPauseAppliesToASerialUnitOnly) {
  const auto& f4t = dr::chamber_dialect("watlow_f4t");
  dr::DeviceSpec spec{.endpoint = "rtu:/dev/ttyUSB0?baud=9600"};
  EXPECT_DOUBLE_EQ(dr::default_request_gap_s(f4t, spec), 0.030);
  spec.endpoint = "tcp://10.0.0.5:502";
  EXPECT_DOUBLE_EQ(dr::default_request_gap_s(f4t, spec), 0.0);
  spec.gateway = true;  // the unit is on the gateway's serial line
  EXPECT_DOUBLE_EQ(dr::default_request_gap_s(f4t, spec), 0.030);
  EXPECT_DOUBLE_EQ(dr::default_request_gap_s(dr::chamber_dialect("generic_plc"), spec), 0.0);
  for (const auto& d : dr::chamber_dialects()) EXPECT_DOUBLE_EQ(d.timing.timeout_s, 0.5);
}

// TestEquity F4T manual p. 14: the word order is set at the panel, Low High by default.
TEST(WordOrder, AnF4tReadsRightInEitherOrderWhenConfiguredAndTheOtherIsRefused) {
  for (const auto order : {mb::WordOrder::cdab, mb::WordOrder::abcd}) {
    F4tRig rig({.float_words = order}, false, sim::UnitLink::tcp_device);
    auto right = rig.driver({.word_order = order});
    auto id = right->identify();
    ASSERT_TRUE(id) << id.error().message;
    EXPECT_TRUE(has(id.value().notes,
                    std::string("word_order = \"") + mb::float_word_order_name(order) + "\""))
        << id.value().notes;
    EXPECT_DOUBLE_EQ(id.value().setpoint_high_c, rig.chamber.config().setpoint_high_c);
    auto s = right->read();
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_NEAR(s.value().air_c, 25.0, 0.01);

    const auto wrong_order =
        order == mb::WordOrder::cdab ? mb::WordOrder::abcd : mb::WordOrder::cdab;
    auto wrong = rig.driver({.word_order = wrong_order});
    auto refused = wrong->identify();
    ASSERT_FALSE(refused) << "read in the wrong order: " << refused.value().setpoint_high_c;
    EXPECT_EQ(refused.error().kind, dr::ErrorKind::protocol);
    EXPECT_TRUE(has(refused.error().message,
                    std::string("set word_order = \"") + mb::float_word_order_name(order) + "\""))
        << refused.error().message;
    EXPECT_FALSE(wrong->read());
  }
}

TEST(WordOrder, ATemperatureInTheWrongOrderIsImplausibleAndTheRightOneIsNot) {
  const mb::Point p{"loop1_pv", 2820, mb::PointType::float32, 1.0, mb::WordOrder::cdab};
  for (double c : {25.0, -40.0, 180.0, 23.7, 0.5, 1234.5}) {
    const auto words = mb::float_to_words(static_cast<float>(c), mb::WordOrder::abcd);
    const double misread = mb::words_to_float(words.data(), mb::WordOrder::cdab);
    EXPECT_FALSE(dr::plausible_temperature(misread)) << c << " misread as " << misread;
    EXPECT_NEAR(dr::in_other_word_order(p, misread), c, 1e-4);
    ASSERT_TRUE(dr::word_order_mismatch(p, misread)) << c;
    EXPECT_FALSE(dr::word_order_mismatch(p, c)) << c;
  }
  EXPECT_FALSE(dr::word_order_mismatch(p, 0.0));  // the same words either way
}

// CCL watlowf4t.py __profile_units:1002: the units register is 6730 over TCP, 14080 over RTU.
// Behind a gateway the unit is on its serial port: `gateway = true` reads 14080.
TEST(Gateway, AnF4tBehindAGatewayReadsItsSerialPortsUnitsRegister) {
  F4tRig rig({.fahrenheit = true}, true, sim::UnitLink::tcp_gateway);
  auto driver = rig.driver({.gateway = true});
  auto id = driver->identify();
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_EQ(id.value().units, "F");
  EXPECT_TRUE(has(id.value().notes, "units register 14080")) << id.value().notes;
  auto s = driver->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR(s.value().air_c, 25.0, 0.01);

  auto unaware = rig.driver({});  // a tcp:// endpoint taken for the unit's own port
  auto refused = unaware->identify();
  ASSERT_FALSE(refused);
  EXPECT_TRUE(has(refused.error().message, "6730")) << refused.error().message;
  EXPECT_TRUE(has(refused.error().message, "gateway = true")) << refused.error().message;
}
