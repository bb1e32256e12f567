// Regression tests for what fuzzing (tests/fuzz, docs/RELIABILITY.md) found in the drivers.
#include <gtest/gtest.h>

#include <stdexcept>

#include "drivers/chamber/chamber_map.hpp"
#include "drivers/modbus/map_overrides.hpp"
#include "drivers/modbus/read_plan.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;

// fuzz_register_maps: an override put a float32 at PDU address 65535, and plan_reads then asked
// for registers 65535..65536, past the Modbus address space (tests/fuzz/findings/...).
TEST(FuzzFindings, APointPastRegister65535IsAConfigError) {
  auto map = cm::f4t();
  mb::PointOverride last{.name = cm::kAir, .address = 65535};
  EXPECT_THROW(mb::apply_overrides(map, {last}), std::invalid_argument);
  mb::PointOverride one_based{.name = cm::kAir, .address = 65535, .one_based = true};
  EXPECT_NO_THROW(mb::apply_overrides(map, {one_based}));  // PDU 65534..65535: the last two
  mb::PointOverride word{.name = cm::kStatus, .address = 65535};
  EXPECT_NO_THROW(mb::apply_overrides(map, {word}));  // one word at the last register
  std::vector<mb::Point> pts;
  for (const auto& [name, p] : map.points()) pts.push_back(p);
  for (const auto& b : mb::plan_reads(pts, 16)) EXPECT_LE(b.start + b.count, 65536);
}
