// Issue 33, points 4 and 5: what a Watlow input measures is read, never assumed. A humidity input
// (F4 input 2, F4T loop 2: TestEquity 101H manual p. 61) is never read as the product
// temperature, the product input is the configuration's explicit choice, humidity control stays
// off during a run; an F4T in Data Map 2 is read from the registers TestEquity lists and nothing
// else (F4T manual p. 47), and a cascade F4T is refused with one line. Each driver against its
// simulator face over Modbus TCP on 127.0.0.1.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/watlow_f4/f4_map.hpp"
#include "drivers/chamber/watlow_f4/watlow_f4_chamber.hpp"
#include "drivers/chamber/watlow_f4t/f4t_map.hpp"
#include "drivers/chamber/watlow_f4t/f4t_part_number.hpp"
#include "drivers/chamber/watlow_f4t/watlow_f4t_chamber.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/faces/watlow_faces.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace {

namespace dr = station::drivers;
namespace sim = station::sim;

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// An F4 face (the F4 map, or an F4T's Data Map 2) with its driver.
struct F4Rig {
  F4Rig(sim::WatlowPanel panel, dr::WatlowInputs inputs, bool map2 = false)
      : face(chamber, panel, 1, map2 ? "watlow_f4t_map2" : "watlow_f4"), server(face, 1) {
    server.start_tcp(0);
    driver = std::make_unique<dr::WatlowF4Chamber>(
        "chamber", map2 ? "watlow_f4t_map2" : "watlow_f4",
        dr::modbus::parse_endpoint(server.endpoint()),
        map2 ? dr::watlow_f4::map2(1, panel.run_event) : dr::watlow_f4::map(1, panel.run_event),
        0.5, nullptr, inputs);
  }
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::F4Face face;
  sim::ModbusServer server;
  std::unique_ptr<dr::WatlowF4Chamber> driver;
};

struct F4tRig {
  F4tRig(sim::WatlowPanel panel, dr::WatlowInputs inputs) : face(chamber, panel), server(face, 1) {
    server.start_tcp(0);
    driver = std::make_unique<dr::WatlowF4tChamber>(
        "chamber", dr::modbus::parse_endpoint(server.endpoint()),
        dr::watlow_f4t::map(1, panel.run_event, false, 1, 2,
                            inputs.product_input != 0 ? inputs.product_input : 2),
        0.5, nullptr, inputs);
  }
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::F4tFace face;
  sim::ModbusServer server;
  std::unique_ptr<dr::WatlowF4tChamber> driver;
};

// A humidity chamber's input 2 reads %RH (register 618 = 1): naming it the product input is
// refused with one line naming the register, nothing is read as a temperature.
TEST(WatlowInputs, F4HumidityInputIsNeverAProductTemperature) {
  F4Rig rig({.humidity = true}, {.product_input = 2});
  auto s = rig.driver->read();
  ASSERT_FALSE(s);
  EXPECT_TRUE(has(s.error().message, "%RH")) << s.error().message;
  EXPECT_TRUE(has(s.error().message, "618")) << s.error().message;
  EXPECT_FALSE(rig.driver->identify());
}

// Without a product input the humidity chamber runs; its humidity control (event 2, left on at
// the panel) is switched off when the run starts, and probe says so.
TEST(WatlowInputs, F4HumidityControlIsKeptOffDuringARun) {
  F4Rig rig({.humidity = true}, {});
  ASSERT_TRUE(rig.face.humidity_on());
  auto id = rig.driver->identify();
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_TRUE(has(id.value().notes, "humidity chamber")) << id.value().notes;
  EXPECT_TRUE(has(id.value().notes, "register 2010")) << id.value().notes;
  auto s = rig.driver->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_TRUE(std::isnan(s.value().product_c));  // no product input: none, never %RH
  ASSERT_TRUE(rig.driver->command({.setpoint_c = 30.0, .run = true}));
  EXPECT_FALSE(rig.face.humidity_on());
  EXPECT_TRUE(rig.chamber.run());
}

// A temperature input 2 chosen as the product: read and converted like the air.
TEST(WatlowInputs, F4TemperatureProductInputIsRead) {
  F4Rig rig({}, {.product_input = 2});
  auto s = rig.driver->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR(s.value().product_c, rig.chamber.product_c(), 0.05 + 1e-9);
}

// The F4T's loop 2 reads %RH (16538 = 1538): refused as the product loop; with none chosen the
// humidity event (16596) goes off at the run's start.
TEST(WatlowInputs, F4tHumidityLoopRefusedAsProductAndSwitchedOff) {
  {
    F4tRig rig({.humidity = true}, {.product_input = 2});
    auto s = rig.driver->read();
    ASSERT_FALSE(s);
    EXPECT_TRUE(has(s.error().message, "%RH")) << s.error().message;
    EXPECT_TRUE(has(s.error().message, "16538")) << s.error().message;
  }
  F4tRig rig({.humidity = true}, {});
  auto id = rig.driver->identify();
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_TRUE(has(id.value().notes, "register 16596")) << id.value().notes;
  ASSERT_TRUE(rig.face.humidity_on());
  ASSERT_TRUE(rig.driver->command({.setpoint_c = 30.0, .run = true}));
  EXPECT_FALSE(rig.face.humidity_on());
}

// A cascade F4T (part number character 12 '7') serves other registers: refused, one line.
TEST(WatlowInputs, F4tCascadeUnitIsRefused) {
  F4tRig rig({.cascade = true}, {});
  auto id = rig.driver->identify();
  ASSERT_FALSE(id);
  EXPECT_TRUE(has(id.error().message, "cascade")) << id.error().message;
  EXPECT_EQ(id.error().message.find('\n'), std::string::npos);
  EXPECT_FALSE(rig.driver->read());
}

// A product loop beyond the controller's loops (two, by its part number) is refused.
TEST(WatlowInputs, F4tProductLoopBeyondTheControllerIsRefused) {
  F4tRig rig({}, {.product_input = 3});
  auto s = rig.driver->read();
  ASSERT_FALSE(s);
  EXPECT_TRUE(has(s.error().message, "2 loop(s)")) << s.error().message;
}

// Data Map 2 serves no 200, 602, 603 (TestEquity p. 47, 61): the driver reads and commands
// without them; the configured limits bound the setpoint; no product is read from 104 (humidity).
TEST(WatlowInputs, F4tMap2ReadsOnlyTheDocumentedSet) {
  F4Rig rig({}, {.setpoint_low_c = -40.0, .setpoint_high_c = 80.0}, true);
  auto s = rig.driver->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR(s.value().air_c, 25.0, 0.05 + 1e-9);
  EXPECT_TRUE(std::isnan(s.value().product_c));
  ASSERT_TRUE(rig.driver->command({.setpoint_c = 70.0, .run = true}));
  EXPECT_NEAR(rig.chamber.setpoint_c(), 70.0, 0.05 + 1e-9);
  s = rig.driver->read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s.value().mode, dr::ChamberMode::constant);  // from the run event: no status 200
  auto beyond = rig.driver->command({.setpoint_c = 85.0});
  ASSERT_FALSE(beyond);
  EXPECT_EQ(beyond.error().kind, dr::ErrorKind::range);
  auto id = rig.driver->identify();
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_DOUBLE_EQ(id.value().setpoint_high_c, 80.0);
  EXPECT_TRUE(has(id.value().notes, "configured")) << id.value().notes;
}

// A cascade F4T has no Data Map 2: every request is refused by the unit, and the driver says
// which map is missing in one line.
TEST(WatlowInputs, F4tMap2OnACascadeUnitIsRefused) {
  F4Rig rig({.cascade = true}, {}, true);
  auto id = rig.driver->identify();
  ASSERT_FALSE(id);
  EXPECT_TRUE(has(id.error().message, "Data Map 2")) << id.error().message;
  EXPECT_TRUE(has(id.error().message, "cascade")) << id.error().message;
  EXPECT_EQ(id.error().message.find('\n'), std::string::npos);
}

// A read writes nothing: probe and the idle watch leave a humidity test someone else runs from
// the panel alone (the chamber running, humidity on); only the station's own start switches it.
TEST(WatlowInputs, AReadNeverSwitchesHumidityOff) {
  F4tRig rig({.humidity = true}, {});
  rig.chamber.set_run(true);
  ASSERT_TRUE(rig.driver->read());
  ASSERT_TRUE(rig.driver->identify());
  ASSERT_TRUE(rig.driver->read());
  EXPECT_TRUE(rig.face.humidity_on());
  F4Rig f4({.humidity = true}, {});
  f4.chamber.set_run(true);
  ASSERT_TRUE(f4.driver->read());
  EXPECT_TRUE(f4.face.humidity_on());
}

// Data Map 2's input 2 is the chamber humidity by its documents: the humidity event is switched
// off when the station starts the chamber, and probe says so whatever the limits.
TEST(WatlowInputs, F4tMap2SwitchesHumidityOffAtTheStart) {
  F4Rig rig({.humidity = true}, {.setpoint_low_c = -40.0, .setpoint_high_c = 80.0}, true);
  auto id = rig.driver->identify();
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_TRUE(has(id.value().notes, "humidity chamber")) << id.value().notes;
  ASSERT_TRUE(rig.face.humidity_on());
  ASSERT_TRUE(rig.driver->command({.run = true}));
  EXPECT_FALSE(rig.face.humidity_on());
}

// A busy unit (exception 06) on Data Map 2 keeps its own message: only "illegal data address"
// says the map is not served.
TEST(WatlowInputs, F4tMap2BusyIsNotCalledACascadeUnit) {
  F4Rig rig({}, {}, true);
  rig.server.inject_exception(6, 1);
  auto s = rig.driver->read();
  ASSERT_FALSE(s);
  EXPECT_FALSE(has(s.error().message, "cascade")) << s.error().message;
  EXPECT_TRUE(rig.driver->read());
}

// The part number (CCL process_controller:861-921): character 7 says whether the loop kinds are
// served (without them a product loop is refused: it could be %RH), character 12 the loops.
TEST(WatlowInputs, F4tPartNumberSaysProfilesAndLoops) {
  const auto parse = [](const std::string& pn) {
    return station::drivers::watlow_f4t::parse_part_number(
        std::vector<std::uint16_t>(pn.begin(), pn.end()));
  };
  EXPECT_FALSE(parse("F4T1L2AAA0A2AAA").profiles);
  EXPECT_TRUE(parse("F4T1L2DAA0A2AAA").profiles);
  EXPECT_EQ(parse("F4T1L2DAA0A3AAA").loops, 3);
  const auto cascade = parse("F4T1L2DAA0A8AAA");
  EXPECT_EQ(cascade.loops, 2);
  EXPECT_EQ(cascade.cascades, 1);
  EXPECT_EQ(parse("F4T1L2DAA0ABAAA").cascades, 2);
}

}  // namespace
