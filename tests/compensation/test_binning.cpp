// Binning: bin edges, trailing bins, gaps, means and the temperature slope.
#include <gtest/gtest.h>

#include <vector>

#include "compensation/binning.hpp"

namespace sc = station::compensation;

namespace {
struct Series {
  std::vector<double> t, rate, temp, grad, extra;
  sc::BinInput view() const { return {t, rate, temp, grad, extra}; }
};

// n samples at 1 Hz from t0; temperature ramps at ramp_c_per_h.
Series ramp(std::size_t n, double t0, double ramp_c_per_h) {
  Series s;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = t0 + static_cast<double>(i);
    s.t.push_back(t);
    s.rate.push_back(static_cast<double>(i % 7));  // mean over a bin is computable by hand
    s.temp.push_back(-40.0 + ramp_c_per_h * (t - t0) / 3600.0);
    s.grad.push_back(0.5);
    s.extra.push_back(2.0 * static_cast<double>(i));
  }
  return s;
}
}  // namespace

TEST(Binning, FullBinsOnlyAndTrailingPartialDropped) {
  EXPECT_EQ(sc::make_bins(ramp(1800, 100.0, 10.0).view()).size(), 3u);
  EXPECT_EQ(sc::make_bins(ramp(1799, 100.0, 10.0).view()).size(), 2u);
  EXPECT_EQ(sc::make_bins(ramp(599, 0.0, 10.0).view()).size(), 0u);
}

TEST(Binning, MeansAndSlope) {
  const auto s = ramp(1200, 1000.0, 20.0);
  const auto bins = sc::make_bins(s.view());
  ASSERT_EQ(bins.size(), 2u);
  const auto& b = bins[1];
  EXPECT_EQ(b.n, 600u);
  EXPECT_TRUE(b.complete);
  EXPECT_DOUBLE_EQ(b.t_start_s, 1600.0);
  EXPECT_NEAR(b.t_mid_s, 1600.0 + 299.5, 1e-9);
  // Samples 600..1199: temperature linear in t, so the mean is the value at the mean time.
  EXPECT_NEAR(b.temp_c, -40.0 + 20.0 * (899.5 / 3600.0), 1e-9);
  EXPECT_NEAR(b.dtdt_c_per_h, 20.0, 1e-9);
  EXPECT_NEAR(b.grad_c, 0.5, 1e-12);
  EXPECT_NEAR(b.extra, 2.0 * 899.5, 1e-9);
  double rate_sum = 0;
  for (int i = 600; i < 1200; ++i) rate_sum += i % 7;
  EXPECT_NEAR(b.rate_dph, rate_sum / 600.0, 1e-12);
  // The range is of the bin's own samples (600 and 1199), exactly as they were given.
  EXPECT_EQ(b.temp_min_c, s.temp[600]);
  EXPECT_EQ(b.temp_max_c, s.temp[1199]);
  EXPECT_EQ(bins[0].temp_max_c, s.temp[599]);
  EXPECT_EQ(b.grad_min_c, 0.5);
  EXPECT_EQ(b.grad_max_c, 0.5);
}

TEST(Binning, RangeOfANonMonotonicBinAndNoGradientSeries) {
  Series s = ramp(600, 0.0, 0.0);
  s.temp[17] = 3.25;    // a spike up
  s.temp[400] = -55.5;  // and one down, the rest at -40
  s.grad[5] = -1.5;
  s.grad[599] = 2.0;
  const auto b = sc::make_bins(s.view()).at(0);
  EXPECT_EQ(b.temp_min_c, -55.5);
  EXPECT_EQ(b.temp_max_c, 3.25);
  EXPECT_EQ(b.grad_min_c, -1.5);
  EXPECT_EQ(b.grad_max_c, 2.0);
  s.grad.clear();
  const auto nograd = sc::make_bins(s.view()).at(0);
  EXPECT_EQ(nograd.grad_min_c, 0.0);
  EXPECT_EQ(nograd.grad_max_c, 0.0);
}

TEST(Binning, GapFlagsAPartialBinAndLeavesNoEmptyOnes) {
  auto s = ramp(2400, 0.0, 10.0);
  // Remove 100 samples inside bin 1 (83 % full) and all of bin 2.
  Series g;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    const bool drop = (i >= 700 && i < 800) || (i >= 1200 && i < 1800);
    if (drop) continue;
    g.t.push_back(s.t[i]);
    g.rate.push_back(s.rate[i]);
    g.temp.push_back(s.temp[i]);
  }
  sc::BinConfig cfg;
  cfg.sample_period_s = 1.0;
  const auto bins = sc::make_bins(g.view(), cfg);
  // Bin 2 held no sample: it is not made; the gap shows as a jump in t_start_s.
  ASSERT_EQ(bins.size(), 3u);
  EXPECT_TRUE(bins[0].complete);
  EXPECT_EQ(bins[1].n, 500u);
  EXPECT_FALSE(bins[1].complete);
  EXPECT_DOUBLE_EQ(bins[2].t_start_s, 1800.0);
  EXPECT_TRUE(bins[2].complete);
}

TEST(Binning, NinetyPercentIsTheThreshold) {
  auto s = ramp(600, 0.0, 0.0);
  Series g;
  for (std::size_t i = 0; i < 600; ++i) {
    if (i >= 10 && i < 70) continue;  // 540 of 600 = exactly 90 %
    g.t.push_back(s.t[i]);
    g.rate.push_back(s.rate[i]);
    g.temp.push_back(s.temp[i]);
  }
  sc::BinConfig cfg;
  cfg.sample_period_s = 1.0;
  EXPECT_TRUE(sc::make_bins(g.view(), cfg).at(0).complete);
  g.t.erase(g.t.begin() + 100);
  g.rate.erase(g.rate.begin() + 100);
  g.temp.erase(g.temp.begin() + 100);
  EXPECT_FALSE(sc::make_bins(g.view(), cfg).at(0).complete);
}

TEST(Binning, InfersThePeriodFromTheMedianStep) {
  std::vector<double> t{0, 2, 4, 6, 9, 10};
  EXPECT_DOUBLE_EQ(sc::effective_sample_period_s(t, {}), 2.0);
}

TEST(Binning, RejectsBadInput) {
  auto s = ramp(10, 0.0, 1.0);
  s.t[5] = s.t[4];
  EXPECT_THROW(sc::make_bins(s.view()), std::invalid_argument);
  auto short_rate = ramp(10, 0.0, 1.0);
  short_rate.rate.pop_back();
  EXPECT_THROW(sc::make_bins(short_rate.view()), std::invalid_argument);
  sc::BinConfig zero;
  zero.width_s = 0;
  EXPECT_THROW(sc::make_bins(ramp(10, 0, 1).view(), zero), std::invalid_argument);
}
