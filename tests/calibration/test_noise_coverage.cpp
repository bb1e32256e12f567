// Monte-Carlo coverage of the reported standard errors under every noise a gyro shows (issue 22):
// for each noise row and protocol, the share of realizations whose true k1 and k0 lie within the
// fit's +-1 and +-2 std_errors. An honest interval covers 68.3 % and 95.4 %; the bands asserted
// are 0.60-0.78 at 1 SE and at least 0.92 at 2 SE. The simulator is the test's own (noise_sim.hpp).
// GYRO_COVERAGE_REALIZATIONS overrides the count (docs/UNCERTAINTY.md's table uses 1000).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <tuple>

#include "noise_sim.hpp"

namespace station::test::noise {
namespace {

constexpr double kB0 = 0.02, kK1 = 1.5e-4, kK0 = 5.5e-3;  // the paper preset's nominal gyro

using Row = NoiseRow;
constexpr const auto& kRows = kNoiseRows;

struct Cover {
  int n = 0, k1_1 = 0, k1_2 = 0, k0_1 = 0, k0_2 = 0, k1_ols_2 = 0;

  double share(int hits) const { return static_cast<double>(hits) / n; }
};

/// The runs with the part's noise given: GYRO_PRIOR_REALIZATIONS, default 200.
int prior_realizations() {
  const char* env = std::getenv("GYRO_PRIOR_REALIZATIONS");
  return env != nullptr ? std::max(50, std::atoi(env)) : 200;
}

int realizations() {
  const char* env = std::getenv("GYRO_COVERAGE_REALIZATIONS");
  return env != nullptr ? std::max(50, std::atoi(env)) : 400;
}

/// The part's noise as the part file would give it: the row's own true N and K (0: no walk), B.
compensation::NoisePrior true_prior(const Levels& lv) {
  compensation::NoisePrior p;
  p.arw_deg_rt_h = lv.arw_dpsh;
  p.rrw_dph_rt_h = lv.rrw_dphpsh;
  if (lv.flicker_b_dph > 0) p.bias_instability_dph = lv.flicker_b_dph;
  return p;
}

Cover coverage(const std::vector<Protocol>& protocols, const Levels& lv, std::uint64_t seed,
               bool with_prior = false) {
  const compensation::ModelData design = protocols_bins(protocols);
  std::mt19937_64 rng(seed);
  Cover c;
  compensation::ModelSpec spec;
  if (with_prior) spec.noise_prior = true_prior(lv);
  for (int r = with_prior ? prior_realizations() : realizations(); r > 0; --r) {
    compensation::ModelData d = design;
    for (std::size_t i = 0; i < d.bias_dph.size(); ++i)
      d.bias_dph[i] = kB0 + kK1 * (d.temp_c[i] - 25) + kK0 * d.grad_c[i];
    add_noise(d, lv, rng);
    const auto fit = compensation::fit_model(d.view(), spec);
    const double e1 = std::abs(fit.coefficients[1] - kK1) / fit.std_errors[1];
    const double e0 = std::abs(fit.coefficients[2] - kK0) / fit.std_errors[2];
    ++c.n;
    c.k1_1 += e1 <= 1;
    c.k1_2 += e1 <= 2;
    c.k0_1 += e0 <= 1;
    c.k0_2 += e0 <= 2;
    c.k1_ols_2 += std::abs(fit.coefficients[1] - kK1) <= 2 * fit.std_errors_ols[1];
  }
  return c;
}

void check(const char* protocol, const std::vector<Protocol>& ps, std::uint64_t seed) {
  for (const Row& row : kRows) {
    const Cover c = coverage(ps, row.levels, seed++);
    std::printf("| %s | %s | %.2f / %.2f | %.2f / %.2f |\n", protocol, row.name, c.share(c.k1_1),
                c.share(c.k1_2), c.share(c.k0_1), c.share(c.k0_2));
    SCOPED_TRACE(std::string(protocol) + ", " + row.name);
    // The bands are the true coverage's; the share is an estimate from c.n realizations. A
    // one-sided binomial test at 1 % per bound: an estimate beyond a bound by more than 2.33 of
    // its binomial sd, sqrt(p (1 - p) / n) at the bound, rejects it (400 realizations: 0.60 ->
    // 0.543, 0.78 -> 0.828, 0.92 -> 0.888).
    auto slack = [&](double p) { return 2.33 * std::sqrt(p * (1 - p) / c.n); };
    // The test can fail: the textbook OLS errors, which assume independent bins, do under
    // Gauss-Markov noise.
    if (row.levels.gm_dph > 0) {
      EXPECT_LT(c.share(c.k1_ols_2), 0.92 - slack(0.92)) << "the OLS errors pass: a weak test";
    }
    const bool known_shortfall = row.levels.rrw_dphpsh >= 0.003;
    for (int k1 : {1, 0}) {
      const double s1 = c.share(k1 != 0 ? c.k1_1 : c.k0_1), s2 = c.share(k1 != 0 ? c.k1_2 : c.k0_2);
      SCOPED_TRACE(k1 != 0 ? "k1" : "k0");
      EXPECT_LE(s1, 0.78 + slack(0.78));
      if (known_shortfall && k1 != 0) {
        // Issue 22, still open: under a strong rate random walk (K = 0.003 deg/h/sqrt h, far
        // above an RLG's) the k1 errors are optimistic: 0.50 / 0.78 on the paper cycle, 0.54 /
        // 0.87 on the ramp pair. The bins cannot tell such a walk from none (test
        // WalkIdentifiability; docs/UNCERTAINTY.md, "What the bins cannot tell"). Held here so
        // that it cannot get worse.
        EXPECT_GE(s1, 0.45);
        EXPECT_GE(s2, 0.72);
        continue;
      }
      EXPECT_GE(s1, 0.60 - slack(0.60));
      EXPECT_GE(s2, 0.92 - slack(0.92));
    }
  }
}

// Issue 32, point 3: with the part's true noise given as a prior (noise_prior.hpp), every cell
// is in the band, the strong walks (K 0.002 and 0.003 deg/h/sqrt(h)) included.
void check_with_prior(const char* protocol, const std::vector<Protocol>& ps, std::uint64_t seed) {
  std::vector<Row> rows(std::begin(kRows), std::end(kRows));
  rows.push_back({"rate random walk K 0.002", {.rrw_dphpsh = 0.002}});
  for (const Row& row : rows) {
    const Cover c = coverage(ps, row.levels, seed++, true);
    std::printf("| %s, part's noise given | %s | %.2f / %.2f | %.2f / %.2f |\n", protocol, row.name,
                c.share(c.k1_1), c.share(c.k1_2), c.share(c.k0_1), c.share(c.k0_2));
    SCOPED_TRACE(std::string(protocol) + ", part's noise given, " + row.name);
    auto slack = [&](double p) { return 2.33 * std::sqrt(p * (1 - p) / c.n); };
    for (const auto& [name, s1, s2] : {std::tuple{"k1", c.share(c.k1_1), c.share(c.k1_2)},
                                       std::tuple{"k0", c.share(c.k0_1), c.share(c.k0_2)}}) {
      SCOPED_TRACE(name);
      EXPECT_LE(s1, 0.78 + slack(0.78));
      EXPECT_GE(s1, 0.60 - slack(0.60));
      EXPECT_GE(s2, 0.92 - slack(0.92));
    }
  }
}

TEST(NoiseCoverage, PaperCycleWithThePartsNoise) {
  check_with_prior("paper cycle", {Protocol{}}, 400);
}

TEST(NoiseCoverage, Ramp10AndRamp20PairWithThePartsNoise) {
  check_with_prior("ramp_10 + ramp_20",
                   {Protocol{.soak_s = 1800}, Protocol{.heat_c_per_h = 20, .soak_s = 1800}}, 500);
}

TEST(NoiseCoverage, PaperCycle) {
  check("paper cycle", {Protocol{}}, 100);
}

TEST(NoiseCoverage, Ramp20) {
  check("ramp_20", {Protocol{.heat_c_per_h = 20, .soak_s = 1800}}, 200);
}

TEST(NoiseCoverage, Ramp10AndRamp20Pair) {
  check("ramp_10 + ramp_20",
        {Protocol{.soak_s = 1800}, Protocol{.heat_c_per_h = 20, .soak_s = 1800}}, 300);
}

}  // namespace
}  // namespace station::test::noise
