// The ADEV curve's long sums (vector_sums.hpp) and the tau-averaged series (BlockAverages):
// the documented order of additions reproduced bit for bit by a scalar loop, whichever vector
// width the machine picked; agreement with plain sequential sums within their rounding bounds;
// the curve's noise identification the same as straight from the rate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "compensation/allan.hpp"
#include "compensation/noise_id.hpp"
#include "compensation/vector_sums.hpp"

namespace station::compensation {
namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;  // unit roundoff

// White FM plus a random walk of the rate (rate random walk): the angle grows as n^1.5, the worst
// case for the cancellation in a difference of angles.
std::vector<double> walk_plus_white(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> y(n);
  double walk = 0;
  for (double& v : y) {
    walk += 0.01 * g(rng);
    v = 15.0 + 0.1 * g(rng) + walk;
  }
  return y;
}

double second_diff(const std::vector<double>& t, std::size_t k, std::size_t m) {
  return t[k + 2 * m] - 2.0 * t[k + m] + t[k];
}
double third_diff(const std::vector<double>& t, std::size_t k, std::size_t m) {
  return t[k + 3 * m] - 3.0 * t[k + 2 * m] + 3.0 * t[k + m] - t[k];
}

// The order vector_sums.hpp documents, in scalar code: term k into partial k mod 32, the 32
// partials added pairwise; the terms in increasing k, or for a factor with chain stride M, k = c +
// b M by blocks of 256 residues c, within a block by b, then c.
double documented_sum(const std::vector<double>& t, std::size_t m, int order, std::size_t stride) {
  double p[32] = {};
  const std::size_t terms = t.size() - static_cast<std::size_t>(order) * m;
  const auto add = [&](std::size_t k) {
    const double d = order == 3 ? third_diff(t, k, m) : second_diff(t, k, m);
    p[k % 32] += d * d;
  };
  if (stride == 0) {
    for (std::size_t k = 0; k < terms; ++k) add(k);
  } else {
    for (std::size_t c0 = 0; c0 < stride; c0 += 256)
      for (std::size_t b = 0; c0 + b * stride < terms; ++b)
        for (std::size_t c = c0; c < c0 + 256 && c + b * stride < terms; ++c) add(c + b * stride);
  }
  for (std::size_t n = 32; n > 1; n /= 2) {
    for (std::size_t i = 0; i < n / 2; ++i) p[i] = p[2 * i] + p[2 * i + 1];
  }
  return p[0];
}

}  // namespace

// Every sum equals the scalar loop in the documented order exactly: no product fused into a sum
// (the AVX-512 clone would fuse one unless compiled with -ffp-contract=off), no lane out of
// order, the tiles (2048 terms) and the tail (N not a multiple of 32) joined in order. Lengths
// around a tile and a lane boundary, octave and arbitrary factors, both orders.
TEST(VectorSums, DifferenceSumsAreTheDocumentedOrderBitForBit) {
  for (const std::size_t n : {std::size_t{5}, std::size_t{100}, std::size_t{2047},
                              std::size_t{2048 + 33}, std::size_t{70001}}) {
    const std::vector<double> theta = integrated_angle(walk_plus_white(n, n));
    for (const int order : {2, 3}) {
      std::vector<std::size_t> ms;
      for (std::size_t m = 1; order * m < theta.size(); m = m < 4 ? m + 1 : m * 3 / 2)
        ms.push_back(m);
      const std::vector<double> sums = difference_sums(theta, ms, order);
      ASSERT_EQ(sums.size(), ms.size());
      for (std::size_t i = 0; i < ms.size(); ++i)
        EXPECT_EQ(sums[i], documented_sum(theta, ms[i], order, 0)) << n << " m " << ms[i];
    }
  }
}

// The chained factors too (issue 37): octave factors up to 2^18 and a list with factors of no
// level (not multiples of 256), lengths that cut a chain's last block within a lane, at a lane
// boundary and at a block boundary, both orders.
TEST(VectorSums, ChainedDifferenceSumsAreTheDocumentedOrderBitForBit) {
  for (const std::size_t n : {std::size_t{16'390}, std::size_t{3 * 16'384 + 17},
                              std::size_t{(1u << 19) + 777}, std::size_t{(1u << 19) + 255}}) {
    const std::vector<double> theta = integrated_angle(walk_plus_white(n, n));
    for (const int order : {2, 3}) {
      std::vector<std::size_t> ms = tau_factors(n, TauSpacing::octave);
      std::erase_if(ms, [&](std::size_t m) { return order * m >= theta.size(); });
      // A factor of no level after the levels (not a multiple of 256).
      if (order * (ms.back() + 1) < theta.size()) ms.push_back(ms.back() + 1);
      const std::vector<std::size_t> strides = difference_sum_strides(ms);
      const std::vector<double> sums = difference_sums(theta, ms, order);
      for (std::size_t i = 0; i < ms.size(); ++i)
        EXPECT_EQ(sums[i], documented_sum(theta, ms[i], order, strides[i])) << n << " m " << ms[i];
    }
  }
}

// The levels as vector_sums.hpp states them: octave 2^13 .. 2^17 at stride 2^13, 2^18 .. 2^22 at
// 2^18, nothing below 2^13; of a decade list only 4 x 10^6 (2^8 x 15625, a level of its own:
// 10^4 .. 2 x 10^6 are no multiples of 256); a level takes only
// multiples of its stride up to 16 times it (17 x 2^13 starts a level of its own).
TEST(VectorSums, ChainStridesAreTheDocumentedLevels) {
  const std::vector<std::size_t> octave = tau_factors(10'000'000, TauSpacing::octave);
  const std::vector<std::size_t> strides = difference_sum_strides(octave);
  for (std::size_t i = 0; i < octave.size(); ++i) {
    const std::size_t m = octave[i];
    const std::size_t want = m < 8192 ? 0 : m <= 131'072 ? 8192 : 262'144;
    EXPECT_EQ(strides[i], want) << m;
  }
  const std::vector<std::size_t> decade = tau_factors(10'000'000, TauSpacing::decade);
  const std::vector<std::size_t> decade_strides = difference_sum_strides(decade);
  for (std::size_t i = 0; i < decade.size(); ++i)
    EXPECT_EQ(decade_strides[i], decade[i] == 4'000'000 ? decade[i] : 0) << decade[i];
  const std::vector<std::size_t> mixed{8192, 8192 + 256, 3 * 8192, 16 * 8192, 17 * 8192};
  EXPECT_EQ(difference_sum_strides(mixed),
            (std::vector<std::size_t>{8192, 8448, 8192, 8192, 17 * 8192}));
}

// Against the plain sequential sum of the same terms: both sum n positive terms, each with a
// relative error of at most (n - 1) u (Higham, Accuracy and Stability of Numerical Algorithms,
// 2nd ed., §4.2, eq. 4.4; the pairwise partials' bound is smaller), so they differ by at most
// 2 (n - 1) u relative.
TEST(VectorSums, DifferenceSumsAgreeWithSequentialSumsWithinTheirBound) {
  const std::vector<double> theta = integrated_angle(walk_plus_white(50'000, 7));
  const std::vector<std::size_t> ms = tau_factors(50'000, TauSpacing::octave);
  const std::vector<double> sums = difference_sums(theta, ms, 2);
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const std::size_t terms = theta.size() - 2 * ms[i];
    double seq = 0;
    for (std::size_t k = 0; k < terms; ++k)
      seq += second_diff(theta, k, ms[i]) * second_diff(theta, k, ms[i]);
    EXPECT_NEAR(sums[i], seq, 2.0 * static_cast<double>(terms - 1) * kU * seq) << ms[i];
  }
}

// The line and lag sums against plain loops, within the same bound (terms of either sign: the
// bound is on the sum of magnitudes).
TEST(VectorSums, LineAndLagSumsAgreeWithPlainLoops) {
  const std::vector<double> y = walk_plus_white(1001, 3);
  const double icpt = 14.9, slope = 1e-4;
  double sy = 0, sty = 0, ay = 0, aty = 0, sx = 0, sxx = 0, sxn = 0, ax = 0, axn = 0;
  for (std::size_t t = 0; t < y.size(); ++t) {
    const double x = y[t] - (icpt + slope * static_cast<double>(t));
    sy += y[t];
    sty += static_cast<double>(t) * y[t];
    ay += std::abs(y[t]);
    aty += std::abs(static_cast<double>(t) * y[t]);
    sx += x;
    sxx += x * x;
    ax += std::abs(x);
    if (t + 1 < y.size()) {
      const double x1 = y[t + 1] - (icpt + slope * static_cast<double>(t + 1));
      sxn += x * x1;
      axn += std::abs(x * x1);
    }
  }
  const double bound = 2.0 * static_cast<double>(y.size()) * kU;
  const LineSums line = line_sums(y);
  EXPECT_NEAR(line.y, sy, bound * ay);
  EXPECT_NEAR(line.ty, sty, bound * aty);
  const LagSums lag = residual_lag_sums(y, icpt, slope);
  EXPECT_NEAR(lag.x, sx, bound * ax);
  EXPECT_NEAR(lag.xx, sxx, bound * sxx);
  EXPECT_NEAR(lag.x_next, sxn, bound * axn);
}

// The sequential sum taken beside the line sums is the plain loop's, and the line sums are
// line_sums', bit for bit, for every length's tail.
TEST(VectorSums, SequentialSumBesideTheLineSumsBitForBit) {
  for (const std::size_t n : {0u, 1u, 15u, 16u, 17u, 1000u, 10'007u}) {
    const std::vector<double> y = walk_plus_white(n, 13);
    double plain = 0;
    for (const double v : y) plain += v;
    const SequentialAndLineSums both = sequential_and_line_sums(y);
    const LineSums line = line_sums(y);
    EXPECT_EQ(both.sequential, plain) << n;
    EXPECT_EQ(both.line.y, line.y) << n;
    EXPECT_EQ(both.line.ty, line.ty) << n;
  }
}

// Averages formed from the previous factor's (octave: pairs; decade's 20 from 10) or from the rate
// (decade's 10 after 4) against the plain mean of each block: a sum of q values in any order is
// within (q - 1) u of the exact sum of magnitudes, so two orders within 2 (q - 1) u.
TEST(BlockAverages, FormedFromThePreviousFactorEqualThePlainMeans) {
  const std::vector<double> y = walk_plus_white(10'007, 11);
  for (const TauSpacing spacing : {TauSpacing::octave, TauSpacing::decade}) {
    BlockAverages averages(y);
    for (const std::size_t m : tau_factors(y.size(), spacing)) {
      const std::span<const double> a = averages.at(m);
      ASSERT_EQ(a.size(), y.size() / m) << m;
      for (std::size_t b = 0; b < a.size(); ++b) {
        double s = 0, abs_s = 0;
        for (std::size_t i = 0; i < m; ++i) {
          s += y[b * m + i];
          abs_s += std::abs(y[b * m + i]);
        }
        const double md = static_cast<double>(m);
        ASSERT_NEAR(a[b], s / md, 2.0 * md * kU * (abs_s / md)) << "m " << m << " block " << b;
      }
    }
  }
}

// The caller's scratch (what overlapping_adev lends) holds the same averages, bit for bit, as
// memory of the averages' own, for every spacing, and is what they are written into.
TEST(BlockAverages, InTheCallersScratchTheSameBits) {
  const std::vector<double> y = walk_plus_white(10'007, 12);
  for (const TauSpacing spacing : {TauSpacing::octave, TauSpacing::decade, TauSpacing::all}) {
    std::vector<double> scratch(y.size() / 2);
    BlockAverages own(y), lent(y, scratch);
    for (const std::size_t m : tau_factors(y.size(), spacing)) {
      const std::span<const double> a = own.at(m), b = lent.at(m);
      ASSERT_EQ(a.size(), b.size()) << m;
      if (m > 1) {
        EXPECT_EQ(b.data(), scratch.data()) << m;
      }
      for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "m " << m << " i " << i;
    }
  }
}

// The curve identifies the noise at every tau as identify_noise and identify_noise_b1 do
// straight from the rate (lag-1 where 30 averages remain, B1 down to 8, carried below): the
// averages formed tau by tau and the one-pass lag-1 sums change nothing but rounding, and no
// seed here sits within rounding of a boundary between two noises.
TEST(OverlappingAdev, NoiseOfEachTauAsIdentifiedFromTheRate) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<double> y = walk_plus_white(20'000, seed);
    const std::vector<std::size_t> ms = tau_factors(y.size(), TauSpacing::octave);
    const std::vector<AdevPoint> curve = overlapping_adev(y, 1.0, ms);
    int last = 0;
    for (const AdevPoint& p : curve) {
      if (const auto id = identify_noise(y, p.m, 2)) {
        EXPECT_EQ(p.noise_id, NoiseIdMethod::lag1) << p.m;
        EXPECT_EQ(p.alpha, id->alpha) << p.m;
      } else if (const auto b1 = identify_noise_b1(y, p.m)) {
        EXPECT_EQ(p.noise_id, NoiseIdMethod::b1) << p.m;
        EXPECT_EQ(p.alpha, b1->alpha) << p.m;
      } else {
        EXPECT_EQ(p.noise_id, NoiseIdMethod::none) << p.m;
        EXPECT_EQ(p.alpha, last) << p.m;
      }
      last = p.alpha;
    }
  }
}

}  // namespace station::compensation
