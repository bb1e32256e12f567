// Issue 36's hostile review, simrig: the configuration it prints gives the simulated table's
// 1000 deg/s rating, and where the table's dialect holds rate demands lower (generic_plc's
// 500 deg/s, docs/DEVICES.md) that figure too, and which one applies. The simulator reads the
// dialect's bound from the document on its own (sim_devices/faces/sim_dialects.cpp), not from the
// driver's map: here the two readings are held equal for every turntable dialect.
#include <gtest/gtest.h>

#include <string>

#include "drivers/registry/dialects.hpp"
#include "sim_devices/faces/sim_dialects.hpp"
#include "sim_devices/sim_world.hpp"

namespace sim = station::sim;

TEST(SimRateLimit, TheSimulatorsReadingOfEachDialectsBoundIsTheDriversOwn) {
  for (const auto& d : station::drivers::turntable_dialects()) {
    SCOPED_TRACE(std::string(d.model));
    EXPECT_EQ(sim::dialect_rate_limit_dps(d.model), d.rate_limit_dps);
  }
  EXPECT_EQ(sim::dialect_rate_limit_dps("generic_plc"), 500.0);  // the control: one has a bound
}

TEST(SimRateLimit, ThePrintedConfigurationSaysWhichRateLimitApplies) {
  sim::SimWorldConfig c;
  c.gyros = 1;
  {
    sim::SimWorld w(c);  // generic_plc: its 500 deg/s below the table's 1000
    const std::string t = w.devices_toml();
    EXPECT_NE(t.find("max_rate_dps = 1000\n"), std::string::npos) << t;
    EXPECT_NE(t.find("# the generic_plc dialect holds rate demands to 500 deg/s (docs/DEVICES.md), "
                     "below the simulated table's 1000 deg/s: 500 deg/s applies\n"),
              std::string::npos)
        << t;
  }
  c.turntable_model = "acutrol3000";  // the unit's own limit, the table's 1000: nothing to add
  sim::SimWorld w(c);
  const std::string t = w.devices_toml();
  EXPECT_NE(t.find("max_rate_dps = 1000\n"), std::string::npos) << t;
  EXPECT_EQ(t.find("applies"), std::string::npos) << t;
}
