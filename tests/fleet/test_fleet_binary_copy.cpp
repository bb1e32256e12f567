// Issue 37: a run's samples travel in COPY's binary format (station/fleet/copy_binary.hpp). The
// types the station writes are the central columns' own; every value arrives as the same double
// or integer, extremes included; a value that is not its column's type refuses the run item with
// nothing of the COPY written, and the others go on; mended, it arrives.
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "station/fleet/copy_binary.hpp"
#include "tests/fleet/fleet_fixture.hpp"

namespace {

namespace fleet = station::fleet;
using station::Database;
using station::testing_support::FleetTest;

class FleetBinaryCopy : public FleetTest {};

std::int64_t central(const std::string& sql) {
  fleet::PgConnection pg(FleetTest::target());
  return pg.exec(sql).integer(0, 0);
}

TEST_F(FleetBinaryCopy, TheSampleTypesAreTheCentralColumnsOwn) {
  const auto& t = fleet::fleet_table("samples");
  const auto names = fleet::split_columns(t.columns);
  ASSERT_EQ(names.size(), std::size(fleet::kCentralSampleTypes));
  fleet::PgConnection pg(target());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto r = pg.exec(
        "SELECT data_type FROM information_schema.columns WHERE table_name = 'samples' AND "
        "column_name = $1",
        {std::string(names[i])});
    ASSERT_EQ(r.rows(), 1) << names[i];
    const char* want = "";
    switch (fleet::kCentralSampleTypes[i]) {
      case fleet::PgType::uuid:
        want = "uuid";
        break;
      case fleet::PgType::text:
        want = "text";
        break;
      case fleet::PgType::float8:
        want = "double precision";
        break;
      case fleet::PgType::int8:
        want = "bigint";
        break;
    }
    EXPECT_EQ(r.text(0, 0), want) << names[i];
  }
}

// Doubles the text form would have to print and parse exactly (the smallest subnormal, the
// largest finite, -0.1, a value one ulp above 1) and the extreme integers arrive as the same
// bits. (Not -0: SQLite stores a REAL zero as the integer 0, so the file holds +0.)
TEST_F(FleetBinaryCopy, ExtremeValuesArriveAsTheSameBits) {
  const auto db = simulated_station("fleet_binary_extremes", 1, 5);
  const double tiny = std::numeric_limits<double>::denorm_min();
  const double big = std::numeric_limits<double>::max();
  const double above_one = std::nextafter(1.0, 2.0);
  {
    Database d(db);
    auto first = d.prepare("SELECT serial, min(t_s) FROM samples");
    ASSERT_TRUE(first.step());
    const std::string serial = first.column_text(0);
    const double t0 = first.column_double(1);
    auto st = d.prepare(
        "UPDATE samples SET rate_dph = ?, temp_c = ?, temp2_c = ?, air_c = ?, net_pulses = ?, "
        "flags = ? WHERE serial = ? AND t_s = ?");
    st.bind(1, tiny).bind(2, big).bind(3, -0.1).bind(4, above_one);
    st.bind(5, std::numeric_limits<std::int64_t>::min())
        .bind(6, std::numeric_limits<std::int64_t>::max());
    st.bind(7, serial).bind(8, t0);
    st.step();
    auto n = d.prepare("SELECT count(*) FROM samples WHERE flags < 0 OR flags > 1000000");
    ASSERT_TRUE(n.step());
    ASSERT_EQ(n.column_int(0), 1);
  }
  const auto sent = forward_all(db, true);
  ASSERT_EQ(sent.failed, 0) << sent.last_error;
  fleet::PgConnection pg(target());
  // float8send: the stored bytes, big-endian, as hex.
  const auto r = pg.exec(
      "SELECT encode(float8send(rate_dph), 'hex'), encode(float8send(temp_c), 'hex'), "
      "encode(float8send(temp2_c), 'hex'), encode(float8send(air_c), 'hex'), net_pulses::text, "
      "flags::text FROM samples ORDER BY t_s LIMIT 1");
  ASSERT_EQ(r.rows(), 1);
  const auto hex = [](double v) { return fmt::format("{:016x}", std::bit_cast<std::uint64_t>(v)); };
  EXPECT_EQ(r.text(0, 0), hex(tiny));
  EXPECT_EQ(r.text(0, 1), hex(big));
  EXPECT_EQ(r.text(0, 2), hex(-0.1));
  EXPECT_EQ(r.text(0, 3), hex(above_one));
  EXPECT_EQ(r.text(0, 4), "-9223372036854775808");
  EXPECT_EQ(r.text(0, 5), "9223372036854775807");
}

// A sample whose integer column holds a fraction (what a hand-edited file could hold) cannot be
// written as a bigint: the run is refused naming the column, no sample of that COPY is on the
// server, the fits go on; mended in the file, the next pass after the back-off sends them all.
TEST_F(FleetBinaryCopy, AValueNotOfItsColumnsTypeRefusesTheRunAndWritesNone) {
  const auto db = simulated_station("fleet_binary_refused", 2, 9);
  std::int64_t local = 0;
  {
    Database d(db);
    d.exec("UPDATE samples SET flags = 1.5 WHERE t_s = (SELECT max(t_s) FROM samples)");
    auto n = d.prepare("SELECT count(*) FROM samples");
    n.step();
    local = n.column_int(0);
  }
  fleet::Forwarder f(db, target(), {.samples = true, .batch_rows = 1'000'000, .station = "t"});
  const auto first = f.pass();
  EXPECT_EQ(first.failed, 1);
  EXPECT_NE(first.last_error.find("flags: 1.5 is not an integer"), std::string::npos)
      << first.last_error;
  EXPECT_EQ(central("SELECT count(*) FROM samples"), 0);
  EXPECT_EQ(first.items, 2) << "the other items (the two fits) go on";
  EXPECT_EQ(central("SELECT count(*) FROM fits"), 2);
  {
    Database d(db);
    d.exec("UPDATE samples SET flags = 0 WHERE flags = 1.5");
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(600));  // the first back-off
  fleet::PassResult later;
  for (int i = 0; i < 20 && central("SELECT count(*) FROM samples") < local; ++i) later = f.pass();
  EXPECT_EQ(later.failed, 0) << later.last_error;
  EXPECT_EQ(central("SELECT count(*) FROM samples"), local);
}

}  // namespace
