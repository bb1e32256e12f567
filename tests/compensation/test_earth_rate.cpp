// Earth-rate component along named and horizontal axes, against hand values.
#include <gtest/gtest.h>

#include <cmath>

#include "compensation/earth_rate.hpp"

namespace sc = station::compensation;

TEST(EarthRate, ConstantMatchesWgs84InDegPerHour) {
  // 7.292115e-5 rad/s * 206264.806"/rad / 3600"/deg * 3600 s/h = 15.0410669 deg/h.
  EXPECT_NEAR(sc::kEarthRateDph, 15.0410669, 1e-6);
}

TEST(EarthRate, UpAxisIsOmegaSinLatitude) {
  const auto up = *sc::axis_from_name("up");
  // Beijing, 39.9 deg N: 15.0410669 * sin(39.9 deg) = 15.0410672 * 0.641450 = 9.64809 deg/h.
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(39.9, up), 9.64809, 1e-4);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(90.0, up), sc::kEarthRateDph, 1e-12);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(0.0, up), 0.0, 1e-12);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(-30.0, up), -sc::kEarthRateDph / 2, 1e-12);
}

TEST(EarthRate, NamedAxesHaveTheirSigns) {
  const double lat = 30.0;  // sin = 1/2, cos = sqrt(3)/2
  const double w = sc::kEarthRateDph;
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(lat, *sc::axis_from_name("down")), -w / 2, 1e-12);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(lat, *sc::axis_from_name("north")),
              w * std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(lat, *sc::axis_from_name("south")),
              -w * std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(lat, *sc::axis_from_name("east")), 0.0, 1e-12);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(lat, *sc::axis_from_name("west")), 0.0, 1e-12);
  EXPECT_FALSE(sc::axis_from_name("sideways").has_value());
}

TEST(EarthRate, HorizontalAxisAtHeadingIsOmegaCosLatCosHeading) {
  // 45 deg N, heading 60 deg: w * cos45 * cos60 = 15.0410669 * 0.7071068 * 0.5 = 5.317820 deg/h.
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(45.0, sc::horizontal_axis(60.0)), 5.317820, 1e-5);
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(45.0, sc::horizontal_axis(90.0)), 0.0, 1e-12);
}

TEST(EarthRate, AxisIsNormalized) {
  const sc::EnuAxis twice_up{0, 0, 2};
  EXPECT_NEAR(sc::earth_rate_along_axis_dph(30.0, twice_up), sc::kEarthRateDph / 2, 1e-12);
}
