// Positions: bias and input-axis misalignment from the Earth rate's projection vs table angle.
// Exact positions give exact figures; simulated ones give figures within their stated errors.
// The generator is this file's own (no sim_devices code), seeded.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "compensation/earth_rate.hpp"
#include "compensation/positions.hpp"

namespace sc = station::compensation;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kW = sc::kEarthRateDph;

// The truth, written independently of positions.hpp's formulas: the Earth rate in ENU dotted
// with the input axis's unit vector, the axis given by azimuth and elevation at each angle.
struct Mount {
  double lat_deg = 45.0;
  double zero_azimuth_deg = 30.0;  ///< the table's zero mark at theta = 0
  double axis_table_deg = 0;       ///< the axis's horizontal direction on the table (ccw)
  double elevation_rad = 0;        ///< pi/2 - tilt for a vertical axis; delta_v for horizontal
  double bias_dph = 0.05;
  double output_dph(double theta_deg) const {
    const double az = (zero_azimuth_deg - axis_table_deg - theta_deg) * kDeg;
    const double e = elevation_rad, phi = lat_deg * kDeg;
    const double east = std::cos(e) * std::sin(az), north = std::cos(e) * std::cos(az);
    const double up = std::sin(e);
    return bias_dph + kW * (0 * east + std::cos(phi) * north + std::sin(phi) * up);
  }
};

std::vector<sc::PositionPoint> positions(const Mount& m, int n, double se_dph,
                                         std::mt19937_64* rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<sc::PositionPoint> p;
  for (int i = 0; i < n; ++i) {
    const double th = 360.0 * i / n;
    p.push_back({th, m.output_dph(th) + (rng ? se_dph * unit(*rng) : 0.0), se_dph});
  }
  return p;
}

sc::PositionSite site(const Mount& m) {
  return {m.lat_deg, m.zero_azimuth_deg};
}

struct Coverage {
  int n = 0, in1 = 0, in2 = 0;
  void add(double estimate, double truth, double se) {
    ++n;
    in1 += std::abs(estimate - truth) <= se;
    in2 += std::abs(estimate - truth) <= 2 * se;
  }
};

// +-1 SE in 0.60..0.78 and +-2 SE at least 0.92 (test_scale_factor.cpp says why these bounds).
void expect_coverage(const Coverage& c, const char* what) {
  const double one = c.in1 / double(c.n), two = c.in2 / double(c.n);
  EXPECT_GE(one, 0.60) << what;
  EXPECT_LE(one, 0.78) << what;
  EXPECT_GE(two, 0.92) << what;
  std::printf("[coverage] %-28s +-1 SE %.3f  +-2 SE %.3f  (%d realizations)\n", what, one, two,
              c.n);
}

constexpr int kRealizations = 1000;

}  // namespace

TEST(Positions, ExactVerticalAxisGivesExactTiltDirectionAndBias) {
  Mount m;
  m.axis_table_deg = 70;             // the tilt leans towards 70 deg on the table
  m.elevation_rad = kPi / 2 - 2e-3;  // tilted 2 mrad from the table's axis
  const auto r = sc::analyze_positions_axis_vertical(positions(m, 8, 1e-3, nullptr), site(m));
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_NEAR(r->tilt_rad, 2e-3, 1e-12);
  EXPECT_NEAR(r->tilt_small_rad, std::sin(2e-3), 1e-12);
  EXPECT_NEAR(r->tilt_direction_table_deg, 70.0, 1e-8);  // 1e-12 rad / 2e-3 rad of phase
  EXPECT_NEAR(r->bias_dph, 0.05, 1e-12);
  EXPECT_TRUE(r->fit.amplitude_resolved);
  EXPECT_EQ(r->fit.dof, 5u);
  EXPECT_DOUBLE_EQ(r->fit.se_scale, 1.0);
}

TEST(Positions, ExactHorizontalAxisGivesExactMisalignments) {
  Mount m;
  m.axis_table_deg = 90 + 0.1;  // nominally at 90 deg, 0.1 deg (1.745 mrad) off in the plane
  m.elevation_rad = 1e-3;       // 1 mrad out of the plane
  const auto pts = positions(m, 12, 1e-3, nullptr);
  const auto r =
      sc::analyze_positions_axis_horizontal(pts, site(m), 90.0, sc::KnownBias{m.bias_dph, 0.0});
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_NEAR(r->in_plane_misalignment_rad, 0.1 * kDeg, 1e-12);
  ASSERT_TRUE(r->out_of_plane_rad.has_value());
  EXPECT_NEAR(*r->out_of_plane_rad, 1e-3, 1e-12);
  EXPECT_NEAR(r->amplitude_ratio, std::cos(1e-3), 1e-12);
  // Without a known bias the constant mixes both: bias_if_level = B + W sin(phi) sin(delta_v).
  const auto u = sc::analyze_positions_axis_horizontal(pts, site(m), 90.0);
  ASSERT_TRUE(u.ok()) << u.error();
  EXPECT_FALSE(u->out_of_plane_rad.has_value());
  EXPECT_NEAR(u->bias_if_level_dph, 0.05 + kW * std::sin(45 * kDeg) * std::sin(1e-3), 1e-12);
}

// A gyro standing up but configured horizontal (review 2026-11-29): its projection is the tilt's
// tiny swing, so the phase, the "heading", is noise; so is an axis 70 deg out of the plane
// (ratio cos 70 = 0.34). Both say why instead of a heading; 50 deg out (0.64) still fits.
TEST(Positions, AHorizontalFitOfAnAxisThatIsNotHorizontalSaysSo) {
  Mount up;
  up.elevation_rad = kPi / 2 - 2e-3;  // vertical, tilted 2 mrad
  std::mt19937_64 rng(7);
  const auto r = sc::analyze_positions_axis_horizontal(positions(up, 8, 5e-3, &rng), site(up), 0);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("not horizontal as configured"), std::string::npos) << r.error();
  Mount steep;
  steep.elevation_rad = 70 * kDeg;
  const auto s70 =
      sc::analyze_positions_axis_horizontal(positions(steep, 8, 1e-3, nullptr), site(steep), 0);
  EXPECT_FALSE(s70.ok());
  steep.elevation_rad = 50 * kDeg;
  const auto s50 =
      sc::analyze_positions_axis_horizontal(positions(steep, 8, 1e-3, nullptr), site(steep), 0);
  ASSERT_TRUE(s50.ok()) << s50.error();
  EXPECT_NEAR(s50->amplitude_ratio, std::cos(50 * kDeg), 1e-9);
}

TEST(Positions, BadInputIsAnErrorResult) {
  Mount m;
  m.elevation_rad = kPi / 2 - 1e-3;
  auto pts = positions(m, 8, 1e-3, nullptr);
  EXPECT_FALSE(sc::analyze_positions_axis_vertical(std::span(pts).first(2), site(m)).ok());
  // 0, 360 and 720 are one angle: cos and sin cannot be told apart from the constant.
  std::vector<sc::PositionPoint> same = {pts[0], pts[0], pts[4]};
  same[1].table_angle_deg = 360;
  const auto d = sc::fit_earth_rate_projection(same);
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().find("2 distinct table angles"), std::string::npos) << d.error();
  pts[2].output_dph = std::numeric_limits<double>::quiet_NaN();
  auto r = sc::analyze_positions_axis_vertical(pts, site(m));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error(), "position 2: output nan is not a finite number");
  pts = positions(m, 8, 1e-3, nullptr);
  pts[1].output_se_dph = -1;
  EXPECT_FALSE(sc::analyze_positions_axis_vertical(pts, site(m)).ok());
  pts = positions(m, 8, 1e-3, nullptr);
  r = sc::analyze_positions_axis_vertical(pts, {90.0, 0.0});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("pole"), std::string::npos) << r.error();
  EXPECT_FALSE(
      sc::analyze_positions_axis_vertical(pts, {std::numeric_limits<double>::infinity(), 0.0})
          .ok());
}

TEST(Positions, MonteCarloVerticalAxisWithinItsErrors) {
  // 8 positions, 1e-3 deg/h per position (long dwells), a 1 mrad tilt: A = 0.0106 deg/h, about
  // 21 SE(A), well inside the delta method's reach.
  std::mt19937_64 rng(1431);
  Mount m;
  m.axis_table_deg = -40;
  m.elevation_rad = kPi / 2 - 1e-3;
  Coverage tilt, dir, bias;
  for (int i = 0; i < kRealizations; ++i) {
    const auto r = sc::analyze_positions_axis_vertical(positions(m, 8, 1e-3, &rng), site(m));
    ASSERT_TRUE(r.ok()) << r.error();
    tilt.add(r->tilt_rad, 1e-3, r->tilt_se_rad);
    dir.add(sc::wrap_deg(r->tilt_direction_table_deg - m.axis_table_deg), 0.0,
            r->tilt_direction_se_deg);
    bias.add(r->bias_dph, m.bias_dph, r->bias_se_dph);
  }
  expect_coverage(tilt, "tilt (axis vertical)");
  expect_coverage(dir, "tilt direction");
  expect_coverage(bias, "bias (axis vertical)");
}

TEST(Positions, MonteCarloHorizontalAxisWithinItsErrors) {
  std::mt19937_64 rng(647);
  Mount m;
  m.axis_table_deg = 0.2;  // nominal 0: 3.5 mrad in the plane
  m.elevation_rad = 2e-3;  // 2 mrad out of the plane, separated by a bias known to 2e-4 deg/h
  std::normal_distribution<double> unit(0.0, 1.0);
  Coverage in_plane, out_of_plane;
  for (int i = 0; i < kRealizations; ++i) {
    const sc::KnownBias known{m.bias_dph + 2e-4 * unit(rng), 2e-4};
    const auto r =
        sc::analyze_positions_axis_horizontal(positions(m, 8, 1e-3, &rng), site(m), 0.0, known);
    ASSERT_TRUE(r.ok() && r->out_of_plane_rad) << r.error();
    in_plane.add(r->in_plane_misalignment_rad, 0.2 * kDeg, r->in_plane_misalignment_se_rad);
    out_of_plane.add(*r->out_of_plane_rad, 2e-3, *r->out_of_plane_se_rad);
  }
  expect_coverage(in_plane, "in-plane misalignment");
  expect_coverage(out_of_plane, "out-of-plane tilt");
}
