// Allan and Hadamard deviations and their confidence intervals against Stable32 on a public
// dataset: allantools' pink_frequency.txt (10,000 fractional-frequency points of simulated
// flicker FM noise; tests/data/allantools_pink_frequency.txt). The reference numbers are
// Stable32 1.60's output for that file as published in the allantools repository
// (tests/pink_frequency/s32_oadev_octave.txt and ohdev.txt, commit 599dc9e), transcribed as
// facts below.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "compensation/allan.hpp"
#include "compensation/noise_edf.hpp"

namespace sc = station::compensation;

namespace {

std::vector<double> pink() {
  std::ifstream in(std::string(STATION_TEST_DATA_DIR) + "/allantools_pink_frequency.txt");
  std::vector<double> y;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') y.push_back(std::stod(line));
  return y;
}

// Stable32: overlapping Allan, confidence factor 0.683, octave AF: AF, alpha, min, sigma, max.
struct S32 {
  std::size_t af;
  int alpha;
  double min, sigma, max;
};
const S32 kOadev[] = {
    {1, -1, 1.3960e-07, 1.4064e-07, 1.4169e-07},   {2, -2, 1.3492e-07, 1.3635e-07, 1.3782e-07},
    {4, -2, 1.3434e-07, 1.3630e-07, 1.3835e-07},   {8, -2, 1.3561e-07, 1.3839e-07, 1.4135e-07},
    {16, -2, 1.3283e-07, 1.3666e-07, 1.4084e-07},  {32, -2, 1.2958e-07, 1.3484e-07, 1.4079e-07},
    {64, 0, 1.2869e-07, 1.3449e-07, 1.4116e-07},   {128, 0, 1.0436e-07, 1.1097e-07, 1.1903e-07},
    {256, 0, 9.1025e-08, 9.9185e-08, 1.1002e-07},  {512, 0, 5.7375e-08, 6.4622e-08, 7.5558e-08},
    {1024, 0, 3.7506e-08, 4.4224e-08, 5.6617e-08}, {2048, 0, 2.5868e-08, 3.2514e-08, 5.0038e-08}};

// Stable32 overlapping Hadamard deviations of the same file, AF 1..6.
const double kOhdev[] = {1.2839e-07, 1.2287e-07, 1.2193e-07, 1.2175e-07, 1.2258e-07, 1.2343e-07};

}  // namespace

// The deviations themselves: Stable32 prints 5 digits, so 1e-4 relative.
TEST(AllanStable32, OverlappingAdevAndHdevMatchStable32) {
  const auto y = pink();
  ASSERT_EQ(y.size(), 10000u);
  std::vector<std::size_t> ms;
  for (const auto& r : kOadev) ms.push_back(r.af);
  const auto pts = sc::overlapping_adev(y, 1.0, ms);
  ASSERT_EQ(pts.size(), std::size(kOadev));
  for (std::size_t i = 0; i < pts.size(); ++i)
    EXPECT_NEAR(pts[i].adev / kOadev[i].sigma, 1.0, 1e-4) << "AF " << kOadev[i].af;
  const std::vector<std::size_t> hm{1, 2, 3, 4, 5, 6};
  const auto h = sc::overlapping_adev(y, 1.0, hm, 0.683, sc::DeviationKind::hdev);
  ASSERT_EQ(h.size(), 6u);
  for (std::size_t i = 0; i < h.size(); ++i)
    EXPECT_NEAR(h[i].adev / kOhdev[i], 1.0, 1e-4) << "AF " << hm[i];
}

// The intervals: Greenhall's edf for the noise Stable32 identified, chi-squared at 68.3 %; each
// half-width (sigma - min, max - sigma) within 2 % of Stable32's at every tau.
TEST(AllanStable32, GreenhallIntervalsMatchStable32WithinTwoPercent) {
  const auto y = pink();
  const double n_phase = static_cast<double>(y.size() + 1);
  for (const auto& r : kOadev) {
    const std::vector<std::size_t> m{r.af};
    const auto pt = sc::overlapping_adev(y, 1.0, m, 0.683)[0];
    const double edf = sc::greenhall_edf(r.alpha, 2, static_cast<double>(r.af), n_phase, true);
    const auto [lo, hi] = sc::chi_squared_interval(pt.adev, edf, 0.683);
    EXPECT_NEAR((pt.adev - lo) / (r.sigma - r.min), 1.0, 0.02) << "AF " << r.af << " edf " << edf;
    EXPECT_NEAR((hi - pt.adev) / (r.max - r.sigma), 1.0, 0.02) << "AF " << r.af << " edf " << edf;
    // And the whole pipeline, with the station's own noise identification.
    EXPECT_EQ(pt.alpha, r.alpha) << "AF " << r.af;
    EXPECT_NEAR((pt.adev - pt.ci_low) / (r.sigma - r.min), 1.0, 0.02) << "AF " << r.af;
    EXPECT_NEAR((pt.ci_high - pt.adev) / (r.max - r.sigma), 1.0, 0.02) << "AF " << r.af;
  }
}

// The noise the lag-1 method finds where at least 30 averages remain, against Stable32's: the
// same at every such tau (beyond, the station carries the last one; Stable32 uses B1 and agrees
// on this file).
TEST(AllanStable32, NoiseIdentificationAgreesWithStable32WhereItHasThirtyPoints) {
  const auto y = pink();
  int agree = 0, tried = 0;
  for (const auto& r : kOadev) {
    const auto id = sc::identify_noise(y, r.af, 2);
    if (!id) continue;
    ++tried;
    agree += id->alpha == r.alpha ? 1 : 0;
    // Flicker FM everywhere in this file: never white PM or flicker PM.
    EXPECT_LE(id->alpha, 0) << "AF " << r.af;
  }
  EXPECT_EQ(tried, 9) << "AF 1..256 leave at least 30 averages of 10,000 points";
  EXPECT_EQ(agree, tried);
}
