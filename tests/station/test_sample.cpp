// The one path from a counter reading to a sample (station/daemon/sample.hpp), which the
// sequencer and `station replay` both run (issue 8: the replay copy skipped the finite check).
#include <gtest/gtest.h>

#include <cmath>

#include "station/daemon/sample.hpp"

namespace {

station::drivers::counters::CounterReading answered(double t1, double t2) {
  station::drivers::counters::CounterReading rd;
  rd.answered = true;
  rd.has_delta = true;
  rd.net_pulses = 12;
  rd.interval_s = 1.0;
  rd.rate_dph = 18.0;
  rd.temps_c = {t1, t2};
  return rd;
}

}  // namespace

TEST(Sample, AChainedReadingGivesRateAndBothSensors) {
  station::SampleRow r;
  const auto rd = answered(20.5, 21.0);
  station::apply_reading(&rd, r);
  EXPECT_EQ(r.flags, 0);
  EXPECT_EQ(r.net_pulses, 12);
  EXPECT_EQ(r.rate_dph, 18.0);
  EXPECT_EQ(r.temp_c, 20.5);
  EXPECT_EQ(r.temp2_c, 21.0);
}

TEST(Sample, ANonFiniteSensorIsNoTemperatureAndAFlag) {
  station::SampleRow r;
  const auto rd = answered(20.5, NAN);
  station::apply_reading(&rd, r);
  EXPECT_FALSE(r.temp_c);
  EXPECT_FALSE(r.temp2_c);
  EXPECT_EQ(r.flags, station::kTempsMissing);
  EXPECT_EQ(r.rate_dph, 18.0);
}

TEST(Sample, NoDeltaNoRateAndALostLatchIsFlagged) {
  station::SampleRow r;
  auto rd = answered(20.5, 21.0);
  rd.has_delta = false;
  rd.status_flags = 1;
  station::apply_reading(&rd, r);
  EXPECT_FALSE(r.rate_dph);
  EXPECT_FALSE(r.net_pulses);
  EXPECT_EQ(r.flags, station::kBoardFault);
  station::SampleRow lost;
  station::apply_reading(nullptr, lost);
  EXPECT_EQ(lost.flags, station::kLatchLost | station::kTempsMissing);
}
