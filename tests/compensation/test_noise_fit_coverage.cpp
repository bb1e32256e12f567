// Do the standard errors of fit_noise_terms (allan.hpp) cover the true IEEE 952 terms, and is a
// quantization term reported only when the data hold one? Monte Carlo with this file's own
// generator of gyro rate noise. And the covariance model behind those errors (noise_fit_cov.hpp)
// against a plain sum over every lag and against Greenhall's edf.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <vector>

#include "compensation/allan.hpp"
#include "compensation/noise_edf.hpp"
#include "compensation/noise_fit_cov.hpp"

namespace sc = station::compensation;

namespace {

// IEEE 952 terms: Q arcsec, N deg/sqrt(h), B deg/h, K deg/h/sqrt(h).
struct NoiseSpec {
  double q_arcsec = 0, n_deg_rth = 0, b_dph = 0, k_dph_rth = 0;
};

// IEEE 952 Table C.2: the AVAR of the four terms at tau (deg/h, s).
double model_avar(const NoiseSpec& s, double tau_s) {
  return 3 * s.q_arcsec * s.q_arcsec / (tau_s * tau_s) + 3600 * s.n_deg_rth * s.n_deg_rth / tau_s +
         2 * std::numbers::ln2 / std::numbers::pi * s.b_dph * s.b_dph +
         s.k_dph_rth * s.k_dph_rth * tau_s / 10800;
}

// Exact AVAR at factor m of an AR(1) rate series with unit variance and coefficient phi:
// (Var S - Cov(S1, S2)) / m^2 for adjacent block sums S of m samples (geometric sums of phi^h).
double ar1_avar(double phi, double m) {
  const double pm = std::pow(phi, m), om = 1 - phi;
  const double var_s = m * (1 + phi) / om - 2 * phi * (1 - pm) / (om * om);
  const double cov = phi * (1 - pm) * (1 - pm) / (om * om);
  return (var_s - cov) / (m * m);
}

// Flicker FM as a sum of first-order Gauss-Markov (AR(1)) processes of equal variance, time
// constants 2 per decade from 1 s to 1e7 s (Keshner, Proc. IEEE 70, 1982: relaxation processes
// spread evenly in log time constant sum to a 1/f spectrum between the extreme corners), the
// variance chosen so that their AVAR equals the B term on average over m = 64 .. m_max (65536:
// the ctest record).
struct Flicker {
  std::vector<double> phi;
  double var = 0;  // of each component, (deg/h)^2
  explicit Flicker(double b_dph, double m_max = 65536) {
    for (double t_s = 1; t_s <= 1.0001e7; t_s *= std::sqrt(10.0)) phi.push_back(std::exp(-1 / t_s));
    double log_sum = 0;
    int count = 0;
    for (double m = 64; m <= m_max; m *= 2, ++count) log_sum += std::log(unit_avar(m));
    var = 2 * std::numbers::ln2 / std::numbers::pi * b_dph * b_dph / std::exp(log_sum / count);
  }
  double unit_avar(double m) const {
    double s = 0;
    for (const double p : phi) s += ar1_avar(p, m);
    return s;
  }
  double avar(double m) const { return var * unit_avar(m); }
};

// The generator's own exact AVAR at factor m (1 Hz): white PM 3 Q^2 / m^2, white FM (60 N)^2 / m,
// flicker as above, and a discrete random walk with step variance q = K^2 / 3600 per second,
// whose AVAR is q (2 m^2 + 1) / (6 m) (its block difference weights the steps 1, 2, .., m, .., 1).
double generator_avar(const NoiseSpec& s, const Flicker& f, double m) {
  const double q = s.k_dph_rth * s.k_dph_rth / 3600;
  return 3 * s.q_arcsec * s.q_arcsec / (m * m) + 3600 * s.n_deg_rth * s.n_deg_rth / m +
         (s.b_dph > 0 ? f.avar(m) : 0.0) + q * (2 * m * m + 1) / (6 * m);
}

// n samples at 1 Hz of rate noise in deg/h: white PM as the difference of white phase noise
// (arcsec per s = deg/h), white FM, flicker FM (stationary start), random-walk FM.
std::vector<double> simulate(const NoiseSpec& s, const Flicker& f, std::size_t n,
                             std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  std::vector<double> state(f.phi.size()), drive(f.phi.size());
  for (std::size_t i = 0; i < state.size(); ++i) {
    state[i] = std::sqrt(f.var) * g(rng);
    drive[i] = std::sqrt(f.var * (1 - f.phi[i] * f.phi[i]));
  }
  const double white = 60 * s.n_deg_rth, step = s.k_dph_rth / 60;
  double walk = 0, phase = s.q_arcsec * g(rng);
  std::vector<double> y(n);
  for (auto& v : y) {
    v = white * g(rng) + (walk += step * g(rng));
    if (s.b_dph > 0)
      for (std::size_t i = 0; i < state.size(); ++i)
        v += (state[i] = f.phi[i] * state[i] + drive[i] * g(rng));
    if (s.q_arcsec > 0) {
      const double next = s.q_arcsec * g(rng);
      v += next - phase;
      phase = next;
    }
  }
  return y;
}

// A gyro whose curve has all three of N, B and K inside a 65536 s record, placed as in the
// reviewer's 2e6 s case scaled to the shorter record (N meets B near 250 s, B meets K near
// 2400 s).
constexpr NoiseSpec kGyro{0.0, 7e-4, 0.004, 0.0056};
constexpr std::size_t kSamples = 65536;

struct Tally {
  int in_1se = 0, in_2se = 0;  // an absent term counts as not covered
  void add(const std::optional<double>& value, const std::optional<double>& se, double truth) {
    if (!value || !se) return;
    const double z = std::fabs(*value - truth) / *se;
    in_1se += z <= 1;
    in_2se += z <= 2;
  }
};

}  // namespace

// What the Monte Carlo below rests on: the generator's AVAR is the model's at every tau of the
// record (within 0.5 %); its flicker part is the B term within 3 % wherever that term is at
// least 10 % of the curve, and misses it by at most 0.3 % of the curve anywhere (below ~30 s
// the shortest time constant, 1 s, lets it fall 10 % under B, where white FM is 60 times B).
// Otherwise a biased B would pass for a coverage failure.
TEST(NoiseFitCoverage, TheGeneratorReproducesTheModelCurve) {
  const Flicker flicker(kGyro.b_dph);
  const double b_term = 2 * std::numbers::ln2 / std::numbers::pi * kGyro.b_dph * kGyro.b_dph;
  for (const std::size_t m : sc::tau_factors(kSamples, sc::TauSpacing::octave)) {
    const double md = static_cast<double>(m), model = model_avar(kGyro, md);
    EXPECT_NEAR(generator_avar(kGyro, flicker, md) / model, 1.0, 0.005) << m;
    EXPECT_NEAR(flicker.avar(md), b_term, 0.003 * model) << m;
    if (b_term >= 0.1 * model) {
      EXPECT_NEAR(flicker.avar(md) / b_term, 1.0, 0.03) << m;
    }
  }
}

// 600 realizations of 65536 s at 1 Hz (octave taus), ~15 s. Binomial sd of a coverage fraction
// from 600: 0.019 at 0.683, 0.0086 at 0.954. Measured over 5 seeds (3000 realizations): +-1 SE
// covers N / B / K 0.71 / 0.71 / 0.69, +-2 SE 0.946 / 0.961 / 0.959, Q reported in 2 % of these
// Q-free records; so the bands [0.60, 0.78], >= 0.92 and <= 10 % sit >= 3 sd away. The WLS
// errors that treat the points as independent (this fit before the sandwich), on this seed:
// 0.53 / 0.53 / 0.44, 0.86 / 0.84 / 0.74, Q in 54 %: they fail all seven bands.
//
// GYRO_NOISE_FIT_REVIEW=R runs instead the reviewer's gyro of issue 32 (N 0.003, B 0.004, K 1e-3,
// 2e6 s records) R times, ~1 s a record (docs/UNCERTAINTY.md's table: R = 200).
TEST(NoiseFitCoverage, StandardErrorsCoverTheTrueTermsAndNoQuantizationIsInvented) {
  const char* review = std::getenv("GYRO_NOISE_FIT_REVIEW");
  const int kRealizations = review != nullptr ? std::max(10, std::atoi(review)) : 600;
  const NoiseSpec gyro = review != nullptr ? NoiseSpec{0.0, 0.003, 0.004, 1e-3} : kGyro;
  const std::size_t samples = review != nullptr ? 2000000 : kSamples;
  const Flicker flicker(gyro.b_dph, static_cast<double>(samples));
  const auto m_list = sc::tau_factors(samples, sc::TauSpacing::octave);
  std::mt19937_64 rng(20240532);
  Tally n, b, k;
  int q_reported = 0;
  for (int r = 0; r < kRealizations; ++r) {
    const auto y = simulate(gyro, flicker, samples, rng);
    const auto t = sc::fit_noise_terms(sc::overlapping_adev(y, 1.0, m_list));
    n.add(t.angle_random_walk_deg_rth, t.angle_random_walk_se, gyro.n_deg_rth);
    b.add(t.bias_instability_dph, t.bias_instability_se, gyro.b_dph);
    k.add(t.rate_random_walk_dph_rth, t.rate_random_walk_se, gyro.k_dph_rth);
    q_reported += t.quantization_arcsec ? 1 : 0;
  }
  const auto frac = [kRealizations](int count) {
    return count / static_cast<double>(kRealizations);
  };
  std::printf(
      "%d realizations: +-1 SE covers N %.3f B %.3f K %.3f, +-2 SE %.3f %.3f %.3f, "
      "Q reported %.3f\n",
      kRealizations, frac(n.in_1se), frac(b.in_1se), frac(k.in_1se), frac(n.in_2se), frac(b.in_2se),
      frac(k.in_2se), frac(q_reported));
  for (const auto& [name, tally] : {std::pair{"N", n}, std::pair{"B", b}, std::pair{"K", k}}) {
    EXPECT_GE(frac(tally.in_1se), 0.60) << name;
    EXPECT_LE(frac(tally.in_1se), 0.78) << name;
    EXPECT_GE(frac(tally.in_2se), 0.92) << name;
  }
  EXPECT_LE(frac(q_reported), 0.10);
}

// A real quantization term (0.01 arcsec: 3 Q^2 is 15 % of the AVAR at 1 s) is found in every
// realization and its interval covers it (measured: 200 of 200 found, +-2 SE covers 0.96). A
// weaker one is not always: 0.005 arcsec (4 % at 1 s) was found in 152 of 200.
TEST(NoiseFitCoverage, ARealQuantizationTermIsFound) {
  constexpr int kRealizations = 50;
  NoiseSpec gyro = kGyro;
  gyro.q_arcsec = 0.01;
  const Flicker flicker(gyro.b_dph);
  const auto m_list = sc::tau_factors(kSamples, sc::TauSpacing::octave);
  std::mt19937_64 rng(7);
  int found = 0;
  Tally q;
  for (int r = 0; r < kRealizations; ++r) {
    const auto y = simulate(gyro, flicker, kSamples, rng);
    const auto t = sc::fit_noise_terms(sc::overlapping_adev(y, 1.0, m_list));
    found += t.quantization_arcsec ? 1 : 0;
    q.add(t.quantization_arcsec, t.quantization_se, gyro.q_arcsec);
  }
  EXPECT_GE(found, kRealizations - 1);
  EXPECT_GE(q.in_2se, 42);  // 0.84 of 50: 3.5 binomial sd below 0.954
}

namespace {

// Brute force of noise_fit_cov.hpp at tau0 = 1 s: C_t(j) of each term at lag j, in long double
// (flicker's nine terms cancel far from the overlap); white and random-walk FM are 0 outside
// -2m < j < 2n (a double second difference of a polynomial of degree <= 3), so only there.
std::array<long double, 4> lag_cov(double m, double n, long double j) {
  std::array<long double, 4> c{};
  const double w[3] = {1, -2, 1};
  const bool overlap = j > -2 * m && j < 2 * n;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      const long double t = j + a * m - b * n, at = std::fabs(t), wab = w[a] * w[b];
      // G per unit theta: Q^2 at t = 0, -0.5 (60 N)^2 |t|, B^2 t^2 ln|t| / 2 pi, K^2 |t|^3 / 43200.
      c[0] += t == 0 ? wab : 0;
      c[1] += overlap ? wab * -1800 * at : 0;
      c[2] += at > 0 ? wab * t * t * std::log(at) / (2 * std::numbers::pi) : 0;
      c[3] += overlap ? wab * at * at * at / 43200 : 0;
    }
  }
  return c;
}

// Cov(s2(m), s2(n)) at theta summed over every lag: 2 / (4 m^2 n^2 M_m M_n) sum count C^2.
double brute_cov(const sc::AdevPoint& p, const sc::AdevPoint& q, const sc::NoiseTheta& theta) {
  const double m = static_cast<double>(p.m), n = static_cast<double>(q.m);
  const double mm = static_cast<double>(p.n), mn = static_cast<double>(q.n);
  long double sum = 0;
  for (double j = -(mn - 1); j <= mm - 1; ++j) {
    const auto c = lag_cov(m, n, j);
    long double cj = 0;
    for (int t = 0; t < 4; ++t) cj += theta[t] * c[t];
    sum += (std::min(mm, mn + j) - std::max(0.0, j)) * cj * cj;
  }
  return static_cast<double>(2 * sum / (4 * m * m * n * n * mm * mn));
}

std::vector<sc::AdevPoint> points_of(std::size_t phase_points, std::vector<std::size_t> m_list) {
  std::vector<sc::AdevPoint> pts;
  for (const std::size_t m : m_list) {
    sc::AdevPoint p;
    p.m = m;
    p.tau_s = static_cast<double>(m);
    p.n = phase_points - 2 * m;
    pts.push_back(p);
  }
  return pts;
}

}  // namespace

// The quadrature (direct sums, Gauss-Legendre pieces, flicker's tail and expansion) against the
// plain sum over every lag, for each term alone and for all four together.
TEST(NoiseFitCovariance, MatchesTheSumOverEveryLag) {
  const auto pts = points_of(20001, {1, 3, 8, 64, 1000, 5000});
  const auto cov = sc::AvarCovariance::of(pts);
  ASSERT_TRUE(cov);
  for (const sc::NoiseTheta theta :
       {sc::NoiseTheta{1, 0, 0, 0}, sc::NoiseTheta{0, 1, 0, 0}, sc::NoiseTheta{0, 0, 1, 0},
        sc::NoiseTheta{0, 0, 0, 1}, sc::NoiseTheta{0.25, 1e-4, 1e-3, 1}}) {
    const Eigen::MatrixXd s = cov->at(theta);
    std::vector<double> diag(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) diag[i] = brute_cov(pts[i], pts[i], theta);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      for (std::size_t j = i; j < pts.size(); ++j) {
        const double want = i == j ? diag[i] : brute_cov(pts[i], pts[j], theta);
        EXPECT_NEAR(s(i, j), want, 1e-3 * std::sqrt(diag[i] * diag[j]))
            << "m " << pts[i].m << " n " << pts[j].m << " theta " << theta[0] << theta[1]
            << theta[2] << theta[3];
      }
    }
  }
}

// An independent reading of the same theory: the variance of one estimate is 2 sigma^4 / edf
// with Greenhall & Riley's edf (noise_edf.hpp) for white FM, flicker FM and random-walk FM
// (alpha 0, -1, -2), within 1 % where their long-sum forms hold (m >= 64).
TEST(NoiseFitCovariance, VarianceAgreesWithGreenhallsEdf) {
  constexpr std::size_t kPhasePoints = 100001;
  const auto pts = points_of(kPhasePoints, {64, 256, 1024, 8192});
  const auto cov = sc::AvarCovariance::of(pts);
  ASSERT_TRUE(cov);
  const int alpha[4] = {2, 0, -1, -2};
  for (int t = 1; t < 4; ++t) {
    sc::NoiseTheta theta{};
    theta[t] = 1;
    const Eigen::MatrixXd s = cov->at(theta);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double tau = pts[i].tau_s;
      const double avar = t == 1   ? 3600 / tau
                          : t == 2 ? 2 * std::numbers::ln2 / std::numbers::pi
                                   : tau / 10800;
      const double edf = sc::greenhall_edf(alpha[t], 2, tau, kPhasePoints, true);
      EXPECT_NEAR(s(i, i) / (2 * avar * avar / edf), 1.0, 0.01) << "term " << t << " m " << tau;
    }
  }
}

// Points without an averaging factor or term count (an analytic curve) have no covariance model.
TEST(NoiseFitCovariance, NeedsTheFactorsOfAnOverlappingCurve) {
  auto pts = points_of(1001, {1, 2, 4});
  EXPECT_TRUE(sc::AvarCovariance::of(pts));
  pts[1].m = 0;
  EXPECT_FALSE(sc::AvarCovariance::of(pts));
}
