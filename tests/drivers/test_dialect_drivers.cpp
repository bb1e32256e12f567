// Issue 20: each dialect's driver against its simulator face on a real transport, where the
// dialects differ from the generic map: deg F and decimal places read from the unit (or refused),
// an ESPEC P300 on a serial line with its RS-485 address and NA: errors, an ACUTROL's rate limit
// and latched interlock fault, and the line client's bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "drivers/ascii/line_client.hpp"
#include "drivers/chamber/espec_p300/espec_p300_chamber.hpp"
#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/watlow_f4/f4_map.hpp"
#include "drivers/chamber/watlow_f4/watlow_f4_chamber.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/turntable/acutrol3000/acutrol3000_table.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/faces/acutrol_face.hpp"
#include "sim_devices/faces/ascii_faces.hpp"
#include "sim_devices/faces/watlow_faces.hpp"
#include "sim_devices/servers/line_server.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace {

namespace dr = station::drivers;
namespace sim = station::sim;

struct F4Rig {
  explicit F4Rig(sim::WatlowPanel panel) : face(chamber, panel), server(face, 1) {
    server.start_tcp(0);
    driver = std::make_unique<dr::WatlowF4Chamber>("chamber", "watlow_f4",
                                                   dr::modbus::parse_endpoint(server.endpoint()),
                                                   dr::watlow_f4::map(1, panel.run_event), 0.5);
  }
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::F4Face face;
  sim::ModbusServer server;
  std::unique_ptr<dr::WatlowF4Chamber> driver;
};

// A unit in deg F with no decimals: 25 C shows as 77 F; read back within half a degree F.
TEST(WatlowF4Dialect, FahrenheitUnitIsConvertedBothWays) {
  F4Rig rig({.decimals = 0, .fahrenheit = true, .run_event = 2});
  auto id = rig.driver->identify();
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_EQ(id.value().units, "F");
  EXPECT_EQ(id.value().decimals, 0);
  EXPECT_NE(id.value().notes.find("converted"), std::string::npos);
  auto s = rig.driver->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR(s.value().air_c, 25.0, 0.5 * 5.0 / 9.0);  // one count is 1 F = 5/9 C
  ASSERT_TRUE(rig.driver->command({.setpoint_c = 40.0, .run = true}));
  EXPECT_NEAR(rig.chamber.setpoint_c(), 40.0, 0.5 * 5.0 / 9.0);  // 104 F
  EXPECT_TRUE(rig.chamber.run());  // through event output 2 (register 2010)
  EXPECT_FALSE(rig.driver->controller_ramp());
}

// Decimal places outside 0..3 (the manual's range): refused with one line naming the register.
TEST(WatlowF4Dialect, ImpossibleDecimalsAreRefusedNotGuessed) {
  F4Rig rig({.decimals = 5});
  auto id = rig.driver->identify();
  ASSERT_FALSE(id);
  EXPECT_NE(id.error().message.find("606/616"), std::string::npos) << id.error().message;
  EXPECT_FALSE(rig.driver->read());
}

// The P300 on a serial line (a pty): the RS-485 address prefix, replies parsed, NA: errors typed.
TEST(EspecP300Dialect, SerialLineWithAddressAndNaErrors) {
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::P300Face face(chamber, 3);
  sim::LineServer server(face);
  server.start_pty(9600);
  dr::EspecP300Chamber p300("chamber", dr::ascii::parse_line_endpoint(server.endpoint()), 3, 0.5);
  ASSERT_TRUE(p300.connect());
  auto s = p300.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR(s.value().air_c, 25.0, 0.05);
  EXPECT_EQ(s.value().mode, dr::ChamberMode::constant);
  ASSERT_TRUE(p300.command({.setpoint_c = -40.0}));
  EXPECT_DOUBLE_EQ(chamber.setpoint_c(), -40.0);
  auto far = p300.command({.setpoint_c = 500.0});  // beyond TEMP?'s high limit: nothing sent
  ASSERT_FALSE(far);
  EXPECT_EQ(far.error().kind, dr::ErrorKind::range);
  server.inject_exception(1, 1);
  auto na = p300.read();
  ASSERT_FALSE(na);
  EXPECT_EQ(na.error().kind, dr::ErrorKind::exception);
  EXPECT_NE(na.error().message.find("NA:CHB NOT READY"), std::string::npos) << na.error().message;
  EXPECT_TRUE(p300.read());  // the next read is fine
  // A unit with another address stays silent: a timeout, not a wrong answer.
  dr::EspecP300Chamber other("chamber", dr::ascii::parse_line_endpoint(server.endpoint()), 4, 0.2);
  auto silent = other.read();
  ASSERT_FALSE(silent);
  EXPECT_EQ(silent.error().kind, dr::ErrorKind::timeout);
}

// The ACUTROL refuses a rate beyond its limit before sending anything; an e-stop is a latched
// interlock fault the station reports and never resets.
TEST(Acutrol3000Dialect, RateLimitAndInterlockFault) {
  sim::TurntableSim table{dr::turntable_map::generic_plc(1)};
  sim::AcutrolFace face(table, 50.0);
  sim::LineServer server(face);
  server.start_tcp(0);
  dr::Acutrol3000Table acutrol("turntable", dr::ascii::parse_line_endpoint(server.endpoint()), 0.5);
  ASSERT_TRUE(acutrol.connect());
  const auto requests = server.requests();
  auto fast = acutrol.command({.mode = dr::TurntableMode::rate, .rate_dps = 60.0});
  ASSERT_FALSE(fast);
  EXPECT_EQ(fast.error().kind, dr::ErrorKind::range);
  EXPECT_EQ(server.requests(), requests);
  ASSERT_TRUE(acutrol.command({.mode = dr::TurntableMode::rate, .rate_dps = 10.0}));
  table.step_to(30.0);
  auto s = acutrol.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s.value().mode, dr::TurntableMode::rate);
  EXPECT_TRUE(s.value().at_rate);
  EXPECT_FALSE(s.value().interlock_open);
  table.set_interlock_open(true);  // the e-stop chain
  s = acutrol.read();
  ASSERT_TRUE(s);
  EXPECT_TRUE(s.value().interlock_open);
  EXPECT_TRUE(s.value().fault);
  auto refused = acutrol.command({.mode = dr::TurntableMode::position, .position_deg = 0.0});
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find(":Interlock:Reset"), std::string::npos);
  auto id = acutrol.identify();
  ASSERT_TRUE(id);
  EXPECT_NE(id.value().find("rate limit 50"), std::string::npos) << id.value();
}

// A device that answers with an endless line: a protocol error at the bound, never a hang or an
// unbounded buffer; the next exchange works.
class Flood final : public sim::LineDevice {
 public:
  std::string request_terminator() const override { return "\r\n"; }
  std::string reply_terminator() const override { return "\r\n"; }
  std::optional<std::string> handle(std::string_view r) override {
    return r == "FLOOD" ? std::string(4000, 'x') : std::string("ok");
  }
  std::string error_reply(std::string_view, int) override { return "NA:"; }
};

TEST(LineClient, OverlongReplyIsProtocolErrorAndTimeoutsReconnect) {
  Flood device;
  sim::LineServer server(device);
  server.start_tcp(0);
  dr::ascii::LineClient client("dev", dr::ascii::parse_line_endpoint(server.endpoint()),
                               dr::ascii::LineFraming{"\r\n", "\r\n", 256}, nullptr, 0.2);
  auto flood = client.query("FLOOD");
  ASSERT_FALSE(flood);
  EXPECT_EQ(flood.error().kind, dr::ErrorKind::protocol);
  EXPECT_EQ(client.query("PING").value(), "ok");
  server.inject_timeouts(3);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(client.query("PING").error().kind, dr::ErrorKind::timeout);
  EXPECT_FALSE(client.connected());  // 3 timeouts in a row on TCP: the socket is renewed
  EXPECT_EQ(client.query("PING").value(), "ok");
  EXPECT_EQ(client.connects(), 2u);
  EXPECT_THROW(dr::ascii::parse_line_endpoint("tcp://chamber.lab:10001"), std::invalid_argument);
}

}  // namespace
