// Tests of overlapping Allan deviation, its intervals, tau sets and the noise terms read off it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "compensation/allan.hpp"
#include "compensation/chi_squared.hpp"
#include "compensation/limits.hpp"

namespace station::compensation {
namespace {

std::vector<double> white_noise(std::size_t n, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> dist(0.0, sigma);
  std::vector<double> y(n);
  for (double& v : y) v = dist(rng);
  return y;
}

// NIST SP 1065 §5.2.4, overlapping AVAR straight from frequency data, brute force O(M m):
// AVAR = 1/(2 m^2 (M-2m+1)) sum_{j} (sum_{i=j}^{j+m-1} (y_{i+m} - y_i))^2.
double direct_oadev(const std::vector<double>& y, std::size_t m) {
  const std::size_t n_outer = y.size() - 2 * m + 1;
  double sum = 0;
  for (std::size_t j = 0; j < n_outer; ++j) {
    double inner = 0;
    for (std::size_t i = j; i < j + m; ++i) inner += y[i + m] - y[i];
    sum += inner * inner;
  }
  const double md = static_cast<double>(m);
  return std::sqrt(sum / (2.0 * md * md * static_cast<double>(n_outer)));
}

TEST(TauFactors, OctaveDecadeAll) {
  // 10 samples: m <= (10-1)/2 = 4 keeps n - 2m + 1 >= 2 terms.
  EXPECT_EQ(tau_factors(10, TauSpacing::octave), (std::vector<std::size_t>{1, 2, 4}));
  EXPECT_EQ(tau_factors(10, TauSpacing::all), (std::vector<std::size_t>{1, 2, 3, 4}));
  EXPECT_EQ(tau_factors(9, TauSpacing::octave), (std::vector<std::size_t>{1, 2, 4}));
  EXPECT_EQ(tau_factors(8, TauSpacing::octave), (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(tau_factors(1000, TauSpacing::decade),
            (std::vector<std::size_t>{1, 2, 4, 10, 20, 40, 100, 200, 400}));
  EXPECT_EQ(tau_factors(100, TauSpacing::decade), (std::vector<std::size_t>{1, 2, 4, 10, 20, 40}));
  EXPECT_EQ(tau_factors(2, TauSpacing::all).size(), 0u);
  EXPECT_EQ(tau_factors(3, TauSpacing::all), (std::vector<std::size_t>{1}));
}

TEST(OverlappingAdev, SmallCaseByHand) {
  // y = 1 3 2 5 4 6 (M = 6, N = 7 angle points), rate 2 Hz so tau0 = 0.5 s.
  // m = 1: differences y_{i+1} - y_i = 2 -1 3 -1 2, squares sum 19, AVAR = 19 / (2*1*5) = 1.9.
  // m = 2: pair sums 4 5 7 9 10 -> (7-4, 9-5, 10-7) = 3 4 3, squares 34, AVAR = 34/(2*4*3) = 17/12.
  // m = 3: (5+4+6) - (1+3+2) = 9, AVAR = 81 / (2*9*1) = 4.5 (a single term).
  // m = 4: N - 2m < 1, skipped.
  const std::vector<double> y{1, 3, 2, 5, 4, 6};
  const std::vector<std::size_t> ms{1, 2, 3, 4};
  const auto pts = overlapping_adev(y, 2.0, ms);
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_NEAR(pts[0].adev, std::sqrt(1.9), 1e-14);
  EXPECT_NEAR(pts[1].adev, std::sqrt(17.0 / 12.0), 1e-14);
  EXPECT_NEAR(pts[2].adev, std::sqrt(4.5), 1e-14);
  EXPECT_DOUBLE_EQ(pts[1].tau_s, 1.0);
  EXPECT_EQ(pts[0].n, 5u);
  EXPECT_EQ(pts[2].n, 1u);
  for (const auto& p : pts) {
    EXPECT_GE(p.edf, 1.0);
    EXPECT_LT(p.ci_low, p.adev);
    EXPECT_GT(p.ci_high, p.adev);
  }
}

TEST(OverlappingAdev, NistSp1065TestSuite) {
  // The 1000-point test data set of NIST SP 1065 §12 (Riley): n_1 = 1234567890,
  // n_{i+1} = 16807 n_i mod 2147483647, y_i = n_i / 2147483647 (fractional frequency, tau0 = 1).
  // Published overlapping ADEV, 7 digits: tau 1: 2.922319e-1, 10: 9.159953e-2, 100: 3.241343e-2.
  std::vector<double> y(1000);
  std::uint64_t n = 1234567890;
  for (double& v : y) {
    v = static_cast<double>(n) / 2147483647.0;
    n = (16807 * n) % 2147483647;
  }
  const std::vector<std::size_t> ms{1, 10, 100};
  const auto pts = overlapping_adev(y, 1.0, ms);
  ASSERT_EQ(pts.size(), 3u);
  // Half a unit of the 7th published digit.
  EXPECT_NEAR(pts[0].adev, 2.922319e-1, 0.5e-7);
  EXPECT_NEAR(pts[1].adev, 9.159953e-2, 0.5e-8);
  EXPECT_NEAR(pts[2].adev, 3.241343e-2, 0.5e-8);
}

TEST(OverlappingAdev, AgreesWithDirectFrequencyFormula) {
  // Large offset on purpose: the mean removal must not change the value.
  auto y = white_noise(1500, 0.7, 42);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] += 15.04 + 0.3 * std::sin(0.01 * i);
  const auto ms = tau_factors(y.size(), TauSpacing::all);
  const auto pts = overlapping_adev(y, 1.0, ms);
  ASSERT_EQ(pts.size(), ms.size());
  for (const auto& p : pts) {
    // Both sum the same squares in different order; ~1e-12 relative rounding is expected.
    EXPECT_NEAR(p.adev / direct_oadev(y, p.m), 1.0, 1e-9) << "m=" << p.m;
  }
}

TEST(OverlappingAdev, WhiteNoiseWithinItsIntervalAndArwRecovered) {
  // White rate noise of sigma per sample at 10 Hz is angle random walk: AVAR(m) = sigma^2 / m.
  constexpr double kSigmaDph = 0.5;
  constexpr double kRateHz = 10.0;
  const auto y = white_noise(200000, kSigmaDph, 7);
  const auto ms = tau_factors(y.size(), TauSpacing::octave);
  const auto pts = overlapping_adev(y, kRateHz, ms, 0.999);
  ASSERT_EQ(pts.size(), ms.size());
  for (const auto& p : pts) {
    const double truth = kSigmaDph / std::sqrt(static_cast<double>(p.m));
    EXPECT_LE(p.ci_low, truth) << "m=" << p.m;
    EXPECT_GE(p.ci_high, truth) << "m=" << p.m;
  }
  // ARW: sigma(1 s) = sigma / sqrt(10 samples) -> N = sigma(1 s) / 60 deg/sqrt(h). The reading is
  // the minimum of sigma_k sqrt(tau_k) over the P points with edf >= 50. With per-point tail
  // probability a = 0.001 / P (union bound) each estimate exceeds truth * sqrt(chi2(a, edf)/edf);
  // and the minimum is no larger than the best-determined point (m = 1), which lies below
  // truth * sqrt(chi2(1 - a, edf_1)/edf_1). Hence the bounds below hold with probability 0.998.
  const NoiseTerms terms = noise_terms(pts);
  ASSERT_TRUE(terms.angle_random_walk_deg_rth.has_value());
  const double arw_truth = kSigmaDph / std::sqrt(kRateHz) / 60.0;
  std::size_t used = 0;
  for (const auto& p : pts) used += p.edf >= 50.0 ? 1 : 0;
  const double a = 0.001 / static_cast<double>(used);
  double low = 1.0;
  for (const auto& p : pts) {
    if (p.edf >= 50.0) low = std::fmin(low, std::sqrt(chi_squared_quantile(a, p.edf) / p.edf));
  }
  const double high = std::sqrt(chi_squared_quantile(1.0 - a, pts[0].edf) / pts[0].edf);
  EXPECT_GE(*terms.angle_random_walk_deg_rth, arw_truth * low);
  EXPECT_LE(*terms.angle_random_walk_deg_rth, arw_truth * high);
}

TEST(OverlappingAdev, AlternatingPulsesExact) {
  // Half a pulse per sample: counts 0 1 0 1 ... of a pulse weight w = 2 arcsec at 1 Hz, i.e. rate
  // w * (0, 1, 0, 1, ...). Mean removed: +-w/2, angle 0, -w/2, 0, -w/2, ... For odd m,
  // theta_{k+2m} - 2 theta_{k+m} + theta_k = +-w in every term, AVAR = w^2 / (2 m^2);
  // for even m all terms vanish.
  constexpr double kW = 2.0;
  std::vector<double> y(101);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] = (i % 2) * kW;
  const std::vector<std::size_t> ms{1, 2, 3, 4, 5, 16, 25};
  const auto pts = overlapping_adev(y, 1.0, ms);
  ASSERT_EQ(pts.size(), ms.size());
  for (const auto& p : pts) {
    const double md = static_cast<double>(p.m);
    const double expected = p.m % 2 ? kW / (std::sqrt(2.0) * md) : 0.0;
    EXPECT_NEAR(p.adev, expected, 1e-12) << "m=" << p.m;
  }
}

TEST(OverlappingAdev, QuantizedPulseSeries) {
  // A gyro at 15 deg/h plus white rate noise, read out as whole pulses of w arcsec per 1 s
  // sample. The noise per sample (sigma * tau0 = w) spreads the angle over many pulses, so the
  // readout error e_k (angle minus whole pulses) is near-uniform on [0, w) and independent
  // (wrapped-Gaussian ripple exp(-2 pi^2) ~ 3e-9). It is white angle noise of variance w^2/12,
  // i.e. quantization Q = w / sqrt(12) (IEEE 952 C.2): AVAR(m) = sigma^2/m + w^2 / (4 m^2).
  constexpr double kW = 1.0;      // arcsec per pulse = (deg/h) * s
  constexpr double kSigma = 1.0;  // deg/h per 1 s sample
  const auto noise = white_noise(100000, kSigma, 11);
  std::vector<double> y(noise.size());
  double angle = 0.37;
  double pulses_before = std::floor(angle / kW);
  for (std::size_t i = 0; i < y.size(); ++i) {
    angle += 15.0 + noise[i];
    const double pulses = std::floor(angle / kW);
    y[i] = (pulses - pulses_before) * kW;
    pulses_before = pulses;
  }
  const std::vector<std::size_t> ms{1, 2, 3, 4, 8};
  const auto pts = overlapping_adev(y, 1.0, ms, 0.999);
  const auto white_only = overlapping_adev(noise, 1.0, ms, 0.999);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double md = static_cast<double>(pts[i].m);
    const double truth = std::sqrt(kSigma * kSigma / md + kW * kW / (4.0 * md * md));
    EXPECT_LE(pts[i].ci_low, truth) << "m=" << pts[i].m;
    EXPECT_GE(pts[i].ci_high, truth) << "m=" << pts[i].m;
  }
  // At m = 1 the quantization adds 25 % to AVAR: well outside the white-only interval.
  EXPECT_GT(pts[0].adev, white_only[0].ci_high);
}

// Analytic IEEE 952 Table C.2 curve: AVAR = 3Q^2/tau^2 + N^2/tau + (0.664 B)^2 + K^2 tau/3,
// with N, K converted to (deg/h, s): N_s = 60 N, K_s^2 = K^2 / 3600 (per second, tau in s).
std::vector<AdevPoint> analytic_curve(double q, double n, double b, double k) {
  std::vector<AdevPoint> pts;
  for (int i = -60; i <= 120; ++i) {  // 1e-6 s .. 1e12 s, 10 points per decade
    const double tau = std::pow(10.0, i / 10.0);
    const double avar = 3.0 * q * q / (tau * tau) + 3600.0 * n * n / tau + 0.664 * 0.664 * b * b +
                        k * k * tau / 3.0 / 3600.0;
    AdevPoint p;
    p.tau_s = tau;
    p.adev = std::sqrt(avar);  // edf = 0: exact point
    pts.push_back(p);
  }
  return pts;
}

TEST(NoiseTerms, RecoversCoefficientsOfAnalyticCurve) {
  constexpr double kQ = 0.01, kN = 0.002, kB = 0.003, kK = 1e-5;
  const NoiseTerms t = noise_terms(analytic_curve(kQ, kN, kB, kK));
  ASSERT_TRUE(t.quantization_arcsec && t.angle_random_walk_deg_rth && t.bias_instability_dph &&
              t.rate_random_walk_dph_rth && t.bias_instability_tau_s);
  // Each reading is sqrt(1 + r) times the truth, r = other terms / own term at the tangent point.
  // For a/tau + b*tau the minimum of r is 2 sqrt(ab) (at tau = sqrt(a/b)); at an end of the grid
  // it is the neighbours' value there. Worked out for these coefficients (tau in s):
  //  N: others/own = 0.02083/tau + 2.78e-4 tau (+K, negligible) -> r >= 4.8e-3;
  //  B: (0.0144/tau + 9.26e-15 tau) / 3.97e-6 -> r >= 5.8e-3;
  //  Q at tau = 1e-6 s: 48 * 1e-6 -> r = 4.8e-5;  K at tau = 1e12 s: 4.3e-4.
  // The 10-per-decade grid adds < 0.2 % to r. Lower bound exact: no line lies above the curve.
  auto check = [](double got, double truth, double r_max) {
    EXPECT_GE(got, truth * (1.0 - 1e-12));
    EXPECT_LE(got, truth * std::sqrt(1.0 + r_max));
  };
  check(*t.quantization_arcsec, kQ, 5e-5);
  check(*t.angle_random_walk_deg_rth, kN, 4.9e-3);
  check(*t.bias_instability_dph, kB, 5.9e-3);
  check(*t.rate_random_walk_dph_rth, kK, 4.4e-4);
  // Minimum of 0.0144/tau + 9.26e-15 tau at tau = sqrt(0.0144 / 9.26e-15) = 1.25e6 s.
  EXPECT_NEAR(std::log10(*t.bias_instability_tau_s), std::log10(1.25e6), 0.1);
}

TEST(NoiseTerms, AbsentTermsStayEmpty) {
  // Pure ARW: slope -1/2 everywhere; no slope near -1, 0 or +1/2.
  const NoiseTerms t = noise_terms(analytic_curve(0.0, 0.002, 0.0, 0.0));
  ASSERT_TRUE(t.angle_random_walk_deg_rth);
  EXPECT_NEAR(*t.angle_random_walk_deg_rth, 0.002, 1e-15);
  EXPECT_FALSE(t.quantization_arcsec);
  EXPECT_FALSE(t.bias_instability_dph);
  EXPECT_FALSE(t.bias_instability_tau_s);
  EXPECT_FALSE(t.rate_random_walk_dph_rth);
  // Pure RRW: only K.
  const NoiseTerms k = noise_terms(analytic_curve(0.0, 0.0, 0.0, 0.02));
  ASSERT_TRUE(k.rate_random_walk_dph_rth);
  EXPECT_NEAR(*k.rate_random_walk_dph_rth, 0.02, 1e-15);
  EXPECT_FALSE(k.angle_random_walk_deg_rth);
  EXPECT_FALSE(noise_terms({}).angle_random_walk_deg_rth);
}

TEST(OverlappingAdev, RejectsBadArguments) {
  const std::vector<double> y{1, 2, 3};
  const std::vector<std::size_t> ms{1};
  EXPECT_THROW(overlapping_adev(y, 0.0, ms), std::invalid_argument);
  EXPECT_THROW(overlapping_adev(y, 1.0, ms, 1.0), std::invalid_argument);
  EXPECT_TRUE(overlapping_adev(std::vector<double>{}, 1.0, ms).empty());
}

// A sample that is not finite is named by its index (the check rides on the mean's sum: only a
// sum that is not finite looks at the samples one by one); finite samples whose sum overflows
// are no sample's fault, and the curve says it overflows.
TEST(OverlappingAdev, NamesTheSampleThatIsNotFinite) {
  const std::vector<std::size_t> ms = {1, 2, 4};
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    std::vector<double> y = white_noise(100, 1.0, 3);
    y[57] = bad;
    try {
      overlapping_adev(y, 1.0, ms);
      ADD_FAILURE() << "no DataError for " << bad;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find("sample 57"), std::string::npos) << e.what();
    }
  }
  const std::vector<double> huge(100, 1e308);
  try {
    overlapping_adev(huge, 1.0, ms);
    ADD_FAILURE() << "no DataError for an overflowing sum";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("overflows"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace station::compensation
