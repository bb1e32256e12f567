// Why k1's errors stay optimistic under a strong rate random walk on the paper cycle (issue 22):
// the bins cannot tell such a walk from none. On one heating ramp dT rises almost linearly in
// time, so a walk's slope goes into k1 and what the residuals keep of it is a few slow wiggles
// that a Gauss-Markov term, or chance, explains as well. This test measures both halves of that
// claim with the station's own error model (compensation/correlated_errors.hpp):
//   - the stakes: under K = 0.003 deg/h/sqrt(h) the true sd of k1 is several times its sd under
//     white noise alone (Monte Carlo over the realizations);
//   - the evidence: the restricted likelihood leans towards walks of that size when the bins
//     hold one, but gives them well under half its weight: most goes to models under which k1
//     is far better determined.
// A weighting of the likelihood that covers k1 under the walk therefore over-covers it under
// white noise (docs/UNCERTAINTY.md, "What the bins cannot tell"). The numbers printed are the
// ones the document quotes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "compensation/correlated_errors.hpp"
#include "noise_sim.hpp"

namespace station::test::noise {
namespace {

constexpr double kK1 = 1.5e-4, kK0 = 5.5e-3, kWalkK = 0.003;

struct Seen {
  double k1_sd = 0;           ///< sd of k1 - truth over the realizations
  double big_walk_share = 0;  ///< mean posterior weight of walks >= 2/3 kWalkK
};

Seen look(const Levels& lv, std::uint64_t seed, int realizations) {
  const compensation::ModelData design = protocols_bins({Protocol{}});
  std::mt19937_64 rng(seed);
  double sum_e2 = 0, sum_share = 0;
  for (int r = 0; r < realizations; ++r) {
    compensation::ModelData d = design;
    for (std::size_t i = 0; i < d.bias_dph.size(); ++i)
      d.bias_dph[i] = 0.02 + kK1 * (d.temp_c[i] - 25) + kK0 * d.grad_c[i];
    add_noise(d, lv, rng);
    const auto fit = compensation::fit_model(d.view(), {});
    sum_e2 += std::pow(fit.coefficients[1] - kK1, 2);
    double big = 0, all = 0;
    for (const auto& c : fit.error_model.mixture) {
      all += c.weight;
      big += c.rrw_dph_per_sqrt_h >= 2.0 / 3 * kWalkK ? c.weight : 0;
    }
    sum_share += all > 0 ? big / all : 0;
  }
  return {std::sqrt(sum_e2 / realizations), sum_share / realizations};
}

TEST(WalkIdentifiability, PaperCycleCannotTellAStrongWalkFromNone) {
  constexpr int kRealizations = 300;
  const Seen white = look({}, 7, kRealizations);
  const Seen walk = look({.rrw_dphpsh = kWalkK}, 8, kRealizations);
  const Seen flicker = look({.flicker_b_dph = 0.006}, 9, kRealizations);
  std::printf(
      "k1 sd: white %.3g, walk K %.3g: %.3g (x %.2f); posterior weight of walks >= "
      "%.3g: white %.2f, walk %.2f, flicker B 0.006 %.2f\n",
      white.k1_sd, kWalkK, walk.k1_sd, walk.k1_sd / white.k1_sd, 2.0 / 3 * kWalkK,
      white.big_walk_share, walk.big_walk_share, flicker.big_walk_share);
  // The stakes: the walk at least doubles k1's true sd (the sd of an sd estimate from 300
  // realizations is 4 %, so 2 is far from chance).
  EXPECT_GT(walk.k1_sd / white.k1_sd, 2.0);
  // The evidence: bins that hold such a walk give it more weight than bins that do not (measured
  // 0.29 against 0.11), but less than half (the mean's sd over 300 realizations is about 0.02).
  // Should a change of the error model make the bins favour the walk they hold, the second
  // check fails, and the coverage test's held cells (test_noise_coverage.cpp) can be asked to
  // meet the band.
  EXPECT_GT(walk.big_walk_share, white.big_walk_share);
  EXPECT_LT(walk.big_walk_share, 0.5);
  // And no rule on that weight can single the walk out: bins of flicker noise, under which k1 is
  // far better determined, give such walks more of it (measured 0.42).
  EXPECT_GT(flicker.big_walk_share, walk.big_walk_share - 0.05);
}

}  // namespace
}  // namespace station::test::noise
