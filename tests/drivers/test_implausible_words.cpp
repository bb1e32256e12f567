// Issue 34 point 2, at the driver: a reading its dialect cannot physically give is outside the
// range the dialect declares (drivers/common/plausible.hpp; docs/DEVICES.md, "Plausible
// readings"), over real sockets with the simulators' faces. The station's rule
// (station/daemon/plausibility.cpp) then takes it out of the reading; here the dialect's part.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/watlow_f4/f4_map.hpp"
#include "drivers/chamber/watlow_f4/watlow_f4_chamber.hpp"
#include "drivers/common/plausible.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/turntable/acutrol3000/acutrol3000_table.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/faces/acutrol_face.hpp"
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
                                                   dr::watlow_f4::map(), 0.5);
  }
  sim::ChamberSim chamber{dr::chamber_map::generic_plc(1)};
  sim::F4Face face;
  sim::ModbusServer server;
  std::unique_ptr<dr::WatlowF4Chamber> driver;
};

// The F4's air register (100) holds a signed 16-bit integer with the unit's decimals (606, 0..3):
// 0x8000 (-32768) is the int16's bottom, the out-of-range mark, never a temperature. With three
// decimals it would read -32.768 C, a cold air a chamber could have; the dialect's range ends at
// -32.767, so it is no reading -- while the chamber's real air and the register's lowest value
// are. (With one decimal the mark, -3276.8 C, is below absolute zero as well.)
TEST(ImplausibleWords, F4Word0x8000IsOutsideTheDialectsRange) {
  F4Rig rig({.decimals = 3});
  auto good = rig.driver->read();
  ASSERT_TRUE(good) << good.error().message;
  EXPECT_FALSE(dr::broken_bound(good.value().air_c, rig.driver->air_range_c()));
  EXPECT_NEAR(rig.driver->setpoint_resolution_c(), 0.001, 1e-12);  // three decimals (606 = 3)

  rig.chamber.set_air_shown_c(-1e6);  // saturates to the word 0x8000 on the F4 face
  auto raw = rig.driver->client().read(dr::watlow_f4::map().at(dr::watlow_f4::kAir));
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(static_cast<std::int16_t>(raw.value()), -32768);
  auto marked = rig.driver->read();
  ASSERT_TRUE(marked) << marked.error().message;
  EXPECT_NEAR(marked.value().air_c, -32.768, 1e-9);
  const auto bound = dr::broken_bound(marked.value().air_c, rig.driver->air_range_c());
  ASSERT_TRUE(bound) << "0x8000 read as " << marked.value().air_c << " C, taken for a reading";
  EXPECT_NEAR(*bound, -32.767, 1e-9);

  rig.chamber.set_air_shown_c(-32.767);  // the lowest value the register carries
  auto lowest = rig.driver->read();
  ASSERT_TRUE(lowest) << lowest.error().message;
  EXPECT_FALSE(dr::broken_bound(lowest.value().air_c, rig.driver->air_range_c()));
}

// Words taken for a float that is none (0x8000 0x8000 as IEEE-754: -4.6e-41) are subnormal: no
// sensor's reading, whatever range it falls in; nor is anything that is not a number.
TEST(ImplausibleWords, SubnormalAndNonFiniteValuesAreNoReadings) {
  const dr::PlausibleRange any{};
  float word_pair = 0;
  const std::uint32_t bits = 0x80008000u;
  std::memcpy(&word_pair, &bits, sizeof bits);
  EXPECT_NEAR(word_pair, -4.6e-41, 1e-42);
  EXPECT_TRUE(dr::broken_bound(word_pair, any));
  EXPECT_TRUE(dr::broken_bound(NAN, any));
  EXPECT_TRUE(dr::broken_bound(INFINITY, any));
  EXPECT_FALSE(dr::broken_bound(0.0, any));
  EXPECT_FALSE(dr::broken_bound(-4.6e-30, any));  // small, but a normal number
  EXPECT_FALSE(dr::broken_bound(1e308, any));
  EXPECT_TRUE(dr::broken_bound(1e308, dr::PlausibleRange{-100, 100}));
}

struct AcutrolRig {
  AcutrolRig() : face(table, kRateLimitDps), server(face) {
    server.start_tcp(0);
    acutrol = std::make_unique<dr::Acutrol3000Table>(
        "turntable", dr::ascii::parse_line_endpoint(server.endpoint()), 0.5);
  }
  static constexpr double kRateLimitDps = 50.0;
  sim::TurntableSim table{dr::turntable_map::generic_plc(1)};
  sim::AcutrolFace face;
  sim::LineServer server;
  std::unique_ptr<dr::Acutrol3000Table> acutrol;
};

// An ACUTROL refuses any rate demand beyond the limit it reports ([ACL] p. 145): a measured rate
// of 1e308 deg/s is no reading. The range is known from the connect (the limit is read there).
TEST(ImplausibleWords, AcutrolRateOf1e308IsOutsideTheUnitsRange) {
  AcutrolRig rig;
  ASSERT_TRUE(rig.acutrol->connect());
  const auto range = rig.acutrol->rate_range_dps();
  EXPECT_DOUBLE_EQ(range.hi, 2 * AcutrolRig::kRateLimitDps);
  EXPECT_DOUBLE_EQ(range.lo, -2 * AcutrolRig::kRateLimitDps);
  auto still = rig.acutrol->read();
  ASSERT_TRUE(still) << still.error().message;
  EXPECT_FALSE(dr::broken_bound(still.value().rate_dps, range));

  rig.table.set_rate_shown_dps(1e308);
  auto lying = rig.acutrol->read();
  // Either the line carrying it is refused as a frame, or the value is outside the range: never a
  // rate taken as read.
  if (lying) {
    const auto bound = dr::broken_bound(lying.value().rate_dps, range);
    ASSERT_TRUE(bound) << "rate " << lying.value().rate_dps << " taken for a reading";
    EXPECT_DOUBLE_EQ(*bound, range.hi);
  }
  rig.table.set_rate_shown_dps(-1e4);  // a plain number, 200 times the limit
  auto fast = rig.acutrol->read();
  ASSERT_TRUE(fast) << fast.error().message;
  EXPECT_TRUE(dr::broken_bound(fast.value().rate_dps, range));
}

}  // namespace
