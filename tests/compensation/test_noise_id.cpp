// Noise identification by the B1 ratio (and R(n)) where fewer than 30 averages remain:
// the expected ratios against values worked by hand, small series worked by hand, and seeded
// series of known noise, whose success rates are derived below.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "compensation/allan.hpp"
#include "compensation/noise_id.hpp"

namespace sc = station::compensation;

namespace {

// b1_expected is a handful of double operations (pow, log, products, one quotient), each within
// an ulp or so, with no cancellation for these N and mu (1 - N^mu and 1 - 2^mu stay away from 0):
// a relative error below 1e-14 (about 45 ulp).
constexpr double kRel = 1e-14;

void expect_rel(double got, double want) {
  EXPECT_NEAR(got, want, kRel * std::abs(want));
}

}  // namespace

// Barnes' B1(N, mu) = N (1 - N^mu) / (2 (N - 1) (1 - 2^mu)) at N = 10, worked by hand:
// mu = 1: 10 (1 - 10) / (18 (1 - 2)) = 5; mu = -1: 10 (0.9) / (18 * 0.5) = 1;
// mu = -2: 10 (0.99) / (18 * 0.75) = 9.9 / 13.5 = 11/15; mu = 0, the limit N ln N / (2 (N-1) ln 2):
// 10 ln 10 / (18 ln 2) = 1.845515608270757 (30 digits by decimal arithmetic).
TEST(B1Expected, TenAveragesByHand) {
  expect_rel(sc::b1_expected(10, 1), 5.0);
  expect_rel(sc::b1_expected(10, -1), 1.0);
  expect_rel(sc::b1_expected(10, -2), 11.0 / 15.0);
  expect_rel(sc::b1_expected(10, 0), 1.845515608270757);
}

// The closed forms of Howe et al. 2000, Table 3 (mu = 2: N (N + 1) / 6; mu = 1: N / 2;
// mu = -1: 1; mu = -2: (N^2 - 1) / (1.5 N (N - 1)) = (N + 1) / (1.5 N)); the flicker limit at
// N = 2^k is exact in rationals: 2^k k / (2 (2^k - 1)), so 4/3 at N = 4, 12/7 at 8, 32/15 at 16.
// At N = 2 every noise has B1 = 1: two averages cannot tell noises apart.
TEST(B1Expected, ClosedFormsAndTheFlickerLimit) {
  for (const double n : {2.0, 3.0, 4.0, 7.0, 29.0, 1000.0}) {
    expect_rel(sc::b1_expected(n, 2), n * (n + 1) / 6);
    expect_rel(sc::b1_expected(n, 1), n / 2);
    expect_rel(sc::b1_expected(n, -1), 1.0);
    expect_rel(sc::b1_expected(n, -2), (n + 1) / (1.5 * n));
  }
  expect_rel(sc::b1_expected(4, 0), 4.0 / 3.0);
  expect_rel(sc::b1_expected(8, 0), 12.0 / 7.0);
  expect_rel(sc::b1_expected(16, 0), 32.0 / 15.0);
  for (const int mu : {1, 0, -1, -2}) expect_rel(sc::b1_expected(2, mu), 1.0);
}

// R(n) = Mod AVAR / AVAR: 1/m for white PM; 1.5 ln(256/27) / (1.038 + 3 ln(pi m)) for flicker PM
// (30 digits by decimal arithmetic: 0.7544427061625540 at m = 1, 0.1844961820213379 at 100);
// 1/2 + 1/(2 m^2) for white FM. By hand at m = 2: the estimator's inner sum over i = 0, 1 of
// theta_{i+4} - 2 theta_{i+2} + theta_i = (y_{i+2} + y_{i+3}) - (y_i + y_{i+1}) is
// -y0 - 2 y1 + 2 y3 + y4, squares 1 + 4 + 4 + 1 = 10 = m^3 + m, so Mod AVAR = 10 / (2 m^4) =
// 0.3125 against AVAR = 1/m = 0.5: 0.625.
TEST(RnExpected, WhitePmFlickerPmAndWhiteFm) {
  expect_rel(sc::rn_expected(2, 100), 0.01);
  expect_rel(sc::rn_expected(1, 1), 0.7544427061625540);
  expect_rel(sc::rn_expected(1, 100), 0.1844961820213379);
  expect_rel(sc::rn_expected(0, 2), 0.625);
  expect_rel(sc::rn_expected(0, 1), 1.0);  // m = 1: Mod AVAR is AVAR
  expect_rel(sc::rn_expected(0, 100), 0.50005);
}

// Ten single samples (m = 1) worked by hand. A ramp 0..9: standard variance 55/6 = 9.1667,
// Allan variance 9 * 1 / (2 * 9) = 0.5, B1 = 18.33, above the random-walk/flicker boundary
// sqrt(5 * 1.8455) = 3.04: random-walk FM. Alternating +1, -1: standard variance 10/9, Allan
// variance 9 * 4 / 18 = 2, B1 = 5/9, below the white-FM/PM boundary sqrt(11/15) = 0.856: PM, and
// at m = 1 R(n) cannot split PM (Mod AVAR = AVAR), so white PM, the conservative one.
TEST(B1Identification, SmallSeriesByHand) {
  std::vector<double> ramp(10), alternating(10);
  for (int i = 0; i < 10; ++i) {
    ramp[i] = i;
    alternating[i] = i % 2 == 0 ? 1.0 : -1.0;
  }
  const auto r = sc::identify_noise_b1(ramp, 1);
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->b1, 55.0 / 6.0 / 0.5, 1e-12);
  EXPECT_EQ(r->alpha, -2);
  EXPECT_EQ(r->averages, 10u);
  EXPECT_FALSE(r->rn);
  const auto a = sc::identify_noise_b1(alternating, 1);
  ASSERT_TRUE(a);
  EXPECT_NEAR(a->b1, 5.0 / 9.0, 1e-12);
  EXPECT_EQ(a->alpha, 2);
  ASSERT_TRUE(a->rn);
  EXPECT_NEAR(*a->rn, 1.0, 1e-12);  // m = 1: Mod AVAR is AVAR
  // Fewer than kMinB1Averages averages, or no variation at all: nothing identified.
  EXPECT_FALSE(sc::identify_noise_b1(ramp, 2));  // 5 averages
  EXPECT_FALSE(sc::identify_noise_b1(std::vector<double>(10, 3.0), 1));
  EXPECT_FALSE(sc::identify_noise_b1(ramp, 0));
}

namespace {

enum class Noise { white_fm, random_walk_fm, white_pm };

// 1,000 samples of unit-variance noise: white FM (white rate), random-walk FM (its running sum),
// white PM (the first difference of white angle).
std::vector<double> seeded(Noise noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> y(1000);
  double sum = 0, prev = g(rng);
  for (double& v : y) {
    const double w = g(rng);
    sum += w;
    v = noise == Noise::white_fm ? w : noise == Noise::random_walk_fm ? sum : w - prev;
    prev = w;
  }
  return y;
}

// alpha -> how many of seeds 1..200 gave it at m = 100 (10 averages) on the ADEV curve, where
// the B1 ratio identifies the noise (fewer than 30 averages).
std::map<int, int> alphas_at_ten_averages(Noise noise) {
  std::map<int, int> count;
  const std::vector<std::size_t> m{100};
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const std::vector<double> y = seeded(noise, seed);
    const auto p = sc::overlapping_adev(y, 1.0, m).at(0);
    EXPECT_EQ(p.noise_id, sc::NoiseIdMethod::b1) << "seed " << seed;
    EXPECT_EQ(p.alpha, sc::identify_noise_b1(y, 100).value().alpha) << "seed " << seed;
    ++count[p.alpha];
  }
  return count;
}

int count_of(const std::map<int, int>& count, int alpha) {
  return count.count(alpha) ? count.at(alpha) : 0;
}

// The right alpha must be the most frequent one and reach the lower 1e-4 binomial bound.
void expect_found(const std::map<int, int>& count, int want, int lower_bound) {
  const int hits = count_of(count, want);
  EXPECT_GE(hits, lower_bound);
  for (const auto& [alpha, n] : count) {
    if (alpha != want) {
      EXPECT_GT(hits, n) << "alpha " << alpha << " beats alpha " << want;
    }
  }
}

}  // namespace

// How often B1 (with R(n) where it says PM) finds the noise at 10 averages: estimated from
// 100,000 seeds (1,000,001 on, disjoint from the 200 below) of exactly these series, standard
// error 0.0016:
//   white FM: alpha 0 in 73.3 %, -1 18.3 %, +1 7.9 % (flicker PM: B1 under the PM boundary and
//             R(n) nearer 0.18 than 0.5), -2 0.5 %;
//   random-walk FM: -2 in 61.6 %, -1 33.3 %, 0 5.1 %;
//   white PM: +2 in 72.2 %, 0 24.8 %, -1 1.6 %, +1 1.5 %.
// Of 200 seeds, exact binomial tails: white FM right 146.7 +- 6.3, at least 123 (P(122 or fewer)
// = 1e-4), so most of them (101 or more fails with probability 2e-12); white FM read as PM
// 15.8 +- 3.8, at most 32 (P(33 or more) = 5e-5), where B1 without R(n)'s white-FM option reads
// 29 % = 58; random-walk FM right 123.2 +- 6.9, at least 97 (P(96 or fewer) = 6e-5): a majority
// cannot be asserted safely (100 or fewer has probability 6e-4); white PM right 144.4 +- 6.3, at
// least 120 (7e-5). The right alpha must also be the commonest: the closest race, random-walk
// against flicker FM, has a margin of 57 +- 13. B1 is a weak test with few averages: with 29
// it finds white FM in 96.9 %, random-walk FM in 77.0 %, white PM in 93.9 %.
TEST(B1Identification, WhiteFmAtTenAveragesInMostSeeds) {
  const auto count = alphas_at_ten_averages(Noise::white_fm);
  expect_found(count, 0, 123);
  EXPECT_LE(count_of(count, 1) + count_of(count, 2), 32);
}

TEST(B1Identification, RandomWalkFmAtTenAverages) {
  expect_found(alphas_at_ten_averages(Noise::random_walk_fm), -2, 97);
}

TEST(B1Identification, WhitePmAtTenAveragesSplitByRn) {
  expect_found(alphas_at_ten_averages(Noise::white_pm), 2, 120);
}
