// Individuals control chart (ISO 7870-2:2023 Table 3) against sums done by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "compensation/control_chart.hpp"

namespace {

using station::compensation::individuals_chart;

// Ten values (the batch data of the NIST/SEMATECH e-Handbook of Statistical Methods, §6.3.2.2).
// By hand: Σx = 508.1, so X̄ = 50.81; the nine moving ranges 2.0 2.3 1.4 3.5 3.4 1.4 0.2 1.2 1.5
// sum to 16.9, so MR̄ = 16.9 / 9; σ̂ = MR̄ / (2/√π).
TEST(ControlChart, IndividualsChartOfTenValues) {
  const std::vector<double> x = {49.6, 47.6, 49.9, 51.3, 47.8, 51.2, 52.6, 52.4, 53.6, 52.1};
  const auto c = individuals_chart(x);
  ASSERT_TRUE(c.has_value());
  const double mr_bar = 16.9 / 9, sigma = mr_bar * std::sqrt(M_PI) / 2;
  EXPECT_NEAR(c->centre, 50.81, 1e-12);
  EXPECT_NEAR(c->mr_bar, mr_bar, 1e-12);
  EXPECT_NEAR(c->sigma, sigma, 1e-12);
  EXPECT_NEAR(c->ucl, 50.81 + 3 * sigma, 1e-12);
  EXPECT_NEAR(c->lcl, 50.81 - 3 * sigma, 1e-12);
  EXPECT_NEAR(station::compensation::kD2Pairs, 1.128, 5e-4);  // ISO 7870-2 Table 2
  EXPECT_TRUE(c->outside.empty());
}

TEST(ControlChart, APointBeyondTheLimitsIsListed) {
  std::vector<double> x(20, 1.0);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += (i % 2 ? 0.01 : -0.01);
  x[13] = 1.2;  // about 5 σ̂ above X̄ (σ̂ from moving ranges of 0.02, and two of 0.2)
  const auto c = individuals_chart(x);
  ASSERT_TRUE(c.has_value());
  ASSERT_EQ(c->outside.size(), 1u);
  EXPECT_EQ(c->outside[0], 13u);
  EXPECT_FALSE(individuals_chart(std::vector<double>{1.0}).has_value());
}

}  // namespace
