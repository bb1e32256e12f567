// Rate-ladder scale factor, bias, nonlinearity, asymmetry and temperature coefficient:
// exact ladders give exact figures; simulated ladders give figures within their stated errors.
// The generator is this file's own (no sim_devices code), seeded, so every run is the same.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "compensation/scale_factor.hpp"

namespace sc = station::compensation;

namespace {

// A gyro: y = K+ x (x > 0) or K- x (x <= 0), plus K B, plus a cubic nonlinearity, x in arcsec/s.
struct TrueGyro {
  double sf_pulse_per_arcsec = 0.95;
  double asymmetry = 0;  ///< (K+ - K-) / K, a fraction
  double bias_dph = 0.8;
  double cubic_per_arcsec2 = 0;  ///< y += K c x^3: an odd nonlinearity
  double output_pps(double x) const {
    const double k = sf_pulse_per_arcsec * (1 + (x > 0 ? 0.5 : -0.5) * asymmetry);
    return k * x + sf_pulse_per_arcsec * (bias_dph + cubic_per_arcsec2 * x * x * x);
  }
};

// The ladder of issue 36: +-1 ... +-300 deg/s, the Earth rate along a vertical axis at 45 deg.
const std::vector<double> kRatesDps = {1, 3, 10, 30, 100, 300, -1, -3, -10, -30, -100, -300};
constexpr double kEarthAlongAxisDph = 15.041067 * 0.70710678;

// Dwell-mean noise: 0.05 pulse/s of quantization and random walk, plus 0.2 ppm of the rate
// (the table's rate jitter over a dwell): heteroscedastic, so the weighting matters.
double dwell_se_pps(double y_pps) {
  return std::hypot(0.05, 2e-7 * y_pps);
}

std::vector<sc::LadderPoint> ladder(const TrueGyro& g, std::mt19937_64* rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<sc::LadderPoint> pts;
  for (double r : kRatesDps) {
    sc::LadderPoint p;
    p.table_rate_dps = r;
    p.earth_rate_dph = kEarthAlongAxisDph;
    const double y = g.output_pps(sc::ladder_input_arcsec_per_s(p));
    p.output_se_pps = dwell_se_pps(y);
    p.output_pps = y + (rng ? p.output_se_pps * unit(*rng) : 0.0);
    pts.push_back(p);
  }
  return pts;
}

// Fractions of |estimate - truth| within 1 and 2 standard errors.
struct Coverage {
  int n = 0, in1 = 0, in2 = 0;
  void add(double estimate, double truth, double se) {
    ++n;
    in1 += std::abs(estimate - truth) <= se;
    in2 += std::abs(estimate - truth) <= 2 * se;
  }
  double one() const { return in1 / double(n); }
  double two() const { return in2 / double(n); }
};

// The acceptance bounds: +-1 SE in 0.60..0.78, +-2 SE at least 0.92. Nominal 68.3 % and 95.4 %;
// the chi2/dof rule (acceptance.hpp) only inflates, so a few % more: with dof = 1 (three
// plateaus) P(|z| < max(1, |w|)) for independent normal z, w is 0.683^2 + 0.267 = 0.733. The
// binomial sd of a fraction near 0.7 over 1000 realizations is 1.4 %. The temperature fit
// takes each plateau's SE after that plateau's own rule (inflated when its chi2/dof > 1), so
// its coverage sits a little above 0.733 again.
constexpr int kRealizations = 1000;
void expect_coverage(const Coverage& c, const char* what) {
  EXPECT_GE(c.one(), 0.60) << what;
  EXPECT_LE(c.one(), 0.78) << what;
  EXPECT_GE(c.two(), 0.92) << what;
  std::printf("[coverage] %-28s +-1 SE %.3f  +-2 SE %.3f  (%d realizations)\n", what, c.one(),
              c.two(), c.n);
}

}  // namespace

TEST(ScaleFactor, ExactLadderGivesExactFigures) {
  TrueGyro g;
  const auto pts = ladder(g, nullptr);
  const auto r = sc::analyze_rate_ladder(pts);
  ASSERT_TRUE(r.ok()) << r.error();
  // Exact to 1e-12 relative. The outputs reach 1e6 pulse/s, so the bias (a / K) and the
  // residuals are exact to 1e-12 of full scale (1.08e6 arcsec/s), not of themselves.
  EXPECT_NEAR(r->sf_pulse_per_arcsec, g.sf_pulse_per_arcsec, 1e-12 * g.sf_pulse_per_arcsec);
  EXPECT_NEAR(r->bias_dph, g.bias_dph, 1e-12 * 300 * 3600);
  EXPECT_LT(r->nonlinearity_max_ppm_fs, 1e-12 * 1e6);
  EXPECT_LT(r->nonlinearity_rms_ppm_fs, 1e-12 * 1e6);
  ASSERT_TRUE(r->asymmetry.has_value()) << r->asymmetry_note;
  EXPECT_NEAR(r->asymmetry->asymmetry_ppm, 0.0, 1e-12 * 1e6);
  EXPECT_EQ(r->points_used, 12u);
  EXPECT_EQ(r->points_excluded, 0u);
  EXPECT_EQ(r->dof, 10u);
  EXPECT_DOUBLE_EQ(r->se_scale, 1.0);  // chi2 = 0: never shrinks the errors
  EXPECT_NEAR(r->full_scale_dps, 300 + kEarthAlongAxisDph / 3600, 1e-9);
  EXPECT_EQ(r->residuals.size(), 12u);
}

TEST(ScaleFactor, ExactAsymmetryIsRecovered) {
  TrueGyro g;
  g.asymmetry = 50e-6;
  const auto r = sc::analyze_rate_ladder(ladder(g, nullptr));
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_TRUE(r->asymmetry.has_value()) << r->asymmetry_note;
  EXPECT_NEAR(r->asymmetry->asymmetry_ppm, 50.0, 1e-12 * 1e6);
  EXPECT_NEAR(r->asymmetry->sf_positive_pulse_per_arcsec, 0.95 * (1 + 25e-6), 1e-12);
  EXPECT_NEAR(r->asymmetry->sf_negative_pulse_per_arcsec, 0.95 * (1 - 25e-6), 1e-12);
}

TEST(ScaleFactor, NonlinearityIsTheLargestDeviationFromTheLeastSquaresLine) {
  // Equal weights: the line by the textbook closed form (slope Sxy/Sxx), independent of QR.
  TrueGyro g;
  g.cubic_per_arcsec2 = 1e-17;  // 1e-17 * (1.08e6)^3 = 12.6 arcsec/s at full scale
  auto pts = ladder(g, nullptr);
  for (auto& p : pts) p.output_se_pps = 1.0;
  const auto r = sc::analyze_rate_ladder(pts);
  ASSERT_TRUE(r.ok()) << r.error();
  double mx = 0, my = 0, sxx = 0, sxy = 0, fs = 0;
  for (const auto& p : pts) mx += sc::ladder_input_arcsec_per_s(p) / 12, my += p.output_pps / 12;
  for (const auto& p : pts) {
    const double x = sc::ladder_input_arcsec_per_s(p);
    sxx += (x - mx) * (x - mx), sxy += (x - mx) * (p.output_pps - my),
        fs = std::max(fs, std::abs(x));
  }
  const double k = sxy / sxx, a = my - k * mx;
  double worst = 0, ss = 0;
  for (const auto& p : pts) {
    const double x = sc::ladder_input_arcsec_per_s(p);
    const double ppm = (p.output_pps - a - k * x) / (k * fs) * 1e6;
    worst = std::max(worst, std::abs(ppm)), ss += ppm * ppm;
  }
  EXPECT_NEAR(r->sf_pulse_per_arcsec, k, 1e-12 * k);
  EXPECT_NEAR(r->nonlinearity_max_ppm_fs, worst, 1e-6 * worst);
  EXPECT_NEAR(r->nonlinearity_rms_ppm_fs, std::sqrt(ss / 12), 1e-6 * worst);
  EXPECT_GT(worst, 1.0);  // a visible nonlinearity, ppm of full scale
}

// The scale factor is the least-squares straight line by definition; the nonlinearity is its
// residual, reported as a figure, not as the scale factor's error: the same points with and
// without a cubic term give the same SE for K, the equal-weight line's under the points' errors
// (closed form: K = sum (x_i - xm) y_i / Sxx, so Var K = sum (x_i - xm)^2 se_i^2 / Sxx^2),
// however large chi2/dof grows. And the points' errors are no weights: errors a factor 6 apart
// (as 9-dof noise estimates are by chance) leave K the textbook slope.
TEST(ScaleFactor, NonlinearityDoesNotInflateTheScaleFactorsError) {
  TrueGyro g;
  const auto linear = ladder(g, nullptr);
  g.cubic_per_arcsec2 = 1e-17;
  auto cubic = ladder(g, nullptr);
  for (std::size_t i = 0; i < cubic.size(); ++i) cubic[i].output_se_pps *= (i % 3 == 0 ? 6 : 1);
  const auto a = sc::analyze_rate_ladder(linear), b = sc::analyze_rate_ladder(cubic);
  ASSERT_TRUE(a.ok() && b.ok());
  struct Line {
    double k, se_k;
  };
  const auto line = [](const std::vector<sc::LadderPoint>& pts) {
    double xm = 0, ym = 0, sxx = 0, sxy = 0, v = 0;
    const double n = static_cast<double>(pts.size());
    for (const auto& p : pts) xm += sc::ladder_input_arcsec_per_s(p) / n, ym += p.output_pps / n;
    for (const auto& p : pts) {
      const double d = sc::ladder_input_arcsec_per_s(p) - xm;
      sxx += d * d, sxy += d * (p.output_pps - ym), v += d * d * p.output_se_pps * p.output_se_pps;
    }
    return Line{sxy / sxx, std::sqrt(v) / sxx};
  };
  const Line la = line(linear), lb = line(cubic);
  EXPECT_GT(b->chi2 / static_cast<double>(b->dof), 100.0);  // the residuals far beyond the noise
  EXPECT_NEAR(b->sf_pulse_per_arcsec, lb.k, 1e-12 * lb.k);
  EXPECT_NEAR(b->sf_se_pulse_per_arcsec, lb.se_k, 1e-9 * lb.se_k);
  EXPECT_NEAR(a->sf_se_pulse_per_arcsec, la.se_k, 1e-9 * la.se_k);
  EXPECT_DOUBLE_EQ(b->se_scale, 1.0);
}

TEST(ScaleFactor, ExcludedPointIsCountedAndNotRead) {
  TrueGyro g;
  auto pts = ladder(g, nullptr);
  pts[3].rate_in_tolerance = false;
  pts[3].output_pps = std::numeric_limits<double>::quiet_NaN();  // a table fault: no reading
  pts[3].table_rate_dps = std::numeric_limits<double>::infinity();
  const auto r = sc::analyze_rate_ladder(pts);
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->points_used, 11u);
  EXPECT_EQ(r->points_excluded, 1u);
  EXPECT_NEAR(r->sf_pulse_per_arcsec, g.sf_pulse_per_arcsec, 1e-12);
}

TEST(ScaleFactor, TooFewPointsIsAnErrorResult) {
  TrueGyro g;
  auto pts = ladder(g, nullptr);
  for (std::size_t i = 2; i < pts.size(); ++i) pts[i].rate_in_tolerance = false;
  const auto r = sc::analyze_rate_ladder(pts);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("2 ladder points in tolerance (10 excluded)"), std::string::npos)
      << r.error();
  EXPECT_THROW((void)r.value(), std::logic_error);
  EXPECT_FALSE(sc::analyze_rate_ladder({}).ok());
  // Three points at one rate: no line through them.
  std::vector<sc::LadderPoint> same(3, pts[0]);
  const auto s = sc::analyze_rate_ladder(same);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("linearly dependent"), std::string::npos) << s.error();
}

TEST(ScaleFactor, NonFiniteInputIsRejectedWithAMessage) {
  TrueGyro g;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto pts = ladder(g, nullptr);
  pts[4].output_pps = nan;
  auto r = sc::analyze_rate_ladder(pts);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error(), "ladder point 4: output_pps nan is not a finite number");
  pts = ladder(g, nullptr);
  pts[1].table_rate_dps = inf;
  r = sc::analyze_rate_ladder(pts);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("ladder point 1: table"), std::string::npos) << r.error();
  pts = ladder(g, nullptr);
  pts[0].output_se_pps = 0;
  r = sc::analyze_rate_ladder(pts);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("output_se_pps 0 is not a positive number"), std::string::npos);
  const std::vector<sc::PlateauScaleFactor> plateaus = {{25, 0.95, 1e-8}, {nan, 0.95, 1e-8}};
  const auto t = sc::fit_scale_factor_vs_temperature(plateaus, 25);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().find("plateau 1: nan is not a finite number"), std::string::npos)
      << t.error();
}

TEST(ScaleFactor, ExactTemperatureCoefficient) {
  const double k0 = 0.95, tc = 5e-6;
  std::vector<sc::PlateauScaleFactor> p;
  for (double t : {-40.0, 25.0, 70.0}) p.push_back({t, k0 * (1 + tc * (t - 25)), 1e-8});
  const auto r = sc::fit_scale_factor_vs_temperature(p, 25.0);
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_NEAR(r->tc_ppm_per_c, 5.0, 1e-12 * 1e6 / 65);
  EXPECT_NEAR(r->sf_ref_pulse_per_arcsec, k0, 1e-12);
  EXPECT_EQ(r->dof, 1u);
  // One plateau, or two at the same temperature: an error result.
  EXPECT_FALSE(sc::fit_scale_factor_vs_temperature(std::span(p).first(1), 25.0).ok());
  p[1].temp_c = p[0].temp_c;
  p.pop_back();
  EXPECT_FALSE(sc::fit_scale_factor_vs_temperature(p, 25.0).ok());
}

TEST(ScaleFactor, MonteCarloScaleFactorAndBiasWithinTheirErrors) {
  std::mt19937_64 rng(20240536);
  TrueGyro g;
  Coverage sf, bias;
  for (int i = 0; i < kRealizations; ++i) {
    const auto r = sc::analyze_rate_ladder(ladder(g, &rng));
    ASSERT_TRUE(r.ok()) << r.error();
    sf.add(r->sf_pulse_per_arcsec, g.sf_pulse_per_arcsec, r->sf_se_pulse_per_arcsec);
    bias.add(r->bias_dph, g.bias_dph, r->bias_se_dph);
  }
  expect_coverage(sf, "scale factor");
  expect_coverage(bias, "bias (ladder intercept)");
}

TEST(ScaleFactor, MonteCarloAsymmetryWithinItsError) {
  std::mt19937_64 rng(77);
  TrueGyro g;
  g.asymmetry = 20e-6;
  Coverage asym;
  for (int i = 0; i < kRealizations; ++i) {
    const auto r = sc::analyze_rate_ladder(ladder(g, &rng));
    ASSERT_TRUE(r.ok() && r->asymmetry) << r.error();
    asym.add(r->asymmetry->asymmetry_ppm, 20.0, r->asymmetry->asymmetry_se_ppm);
  }
  expect_coverage(asym, "asymmetry");
}

TEST(ScaleFactor, MonteCarloTemperatureCoefficientWithinItsError) {
  // Three plateaus (cold, room, hot) as the acceptance protocol runs them, a ladder at each.
  std::mt19937_64 rng(4242);
  const double k0 = 0.95, tc = 5e-6;
  Coverage tcc, k_ref;
  for (int i = 0; i < kRealizations; ++i) {
    std::vector<sc::PlateauScaleFactor> plateaus;
    for (double t : {-40.0, 25.0, 70.0}) {
      TrueGyro g;
      g.sf_pulse_per_arcsec = k0 * (1 + tc * (t - 25));
      const auto r = sc::analyze_rate_ladder(ladder(g, &rng));
      ASSERT_TRUE(r.ok()) << r.error();
      plateaus.push_back({t, r->sf_pulse_per_arcsec, r->sf_se_pulse_per_arcsec});
    }
    const auto f = sc::fit_scale_factor_vs_temperature(plateaus, 25.0);
    ASSERT_TRUE(f.ok()) << f.error();
    tcc.add(f->tc_ppm_per_c, tc * 1e6, f->tc_se_ppm_per_c);
    k_ref.add(f->sf_ref_pulse_per_arcsec, k0, f->sf_ref_se_pulse_per_arcsec);
  }
  expect_coverage(tcc, "temperature coefficient");
  expect_coverage(k_ref, "scale factor at T_ref");
}

// A ladder read while the gyro warms: each rate one way then the other (+1 -1 +10 -10 +100
// -100, the station's order), the temperature rising 0.5 C from point to point, and K
// changing by TC = 4 ppm/C with it. The pair +-100 deg/s is read 0.5 C apart: the plain fit
// takes TC x 0.5 C = 2 ppm for asymmetry; brought to Tc with the TC, the points give the truth
// (an exact ladder: K to 1e-12 of K(Tc), the asymmetry to 1e-4 ppm: the correction takes K(Tc)
// for K(25 C), an error of TC (Tc - 25) x TC dT = 2e-11 of K, 2e-5 ppm).
TEST(ScaleFactor, ADriftingLadderIsBroughtToItsSlopesTemperature) {
  constexpr double kK = 0.95, kTc = 4.0, kStepC = 0.5, kT0 = 20.0;
  std::vector<sc::LadderPoint> pts;
  int i = 0;
  for (double r : {1.0, -1.0, 10.0, -10.0, 100.0, -100.0}) {
    sc::LadderPoint p;
    p.table_rate_dps = r;
    p.earth_rate_dph = 0;
    p.temp_c = kT0 + kStepC * i++;
    p.output_pps = kK * (1 + kTc * 1e-6 * (p.temp_c - 25.0)) * 3600 * r;
    p.output_se_pps = 0.02;
    pts.push_back(p);
  }
  const double tc_c = sc::ladder_slope_temp_c(pts);
  // Sxx-weighted: the +-100 points (22.0 and 22.5 C) carry nearly all of it.
  EXPECT_NEAR(tc_c, 22.24, 0.01);
  const auto plain = sc::analyze_rate_ladder(pts);
  ASSERT_TRUE(plain) << plain.error();
  ASSERT_TRUE(plain->asymmetry);
  EXPECT_NEAR(plain->drift_c, 2.5, 1e-12);
  EXPECT_FALSE(plain->drift_corrected);
  EXPECT_NEAR(plain->asymmetry->asymmetry_ppm, -kTc * kStepC, 0.05);  // -2 ppm, not 0
  EXPECT_FALSE(plain->asymmetry->judged);  // 2.5 C > kMaxUncorrectedDriftC, no TC given
  EXPECT_NE(plain->asymmetry_note.find("not judged"), std::string::npos);

  const auto fixed = sc::analyze_rate_ladder(pts, sc::LadderTemperatureModel{kTc, 0.0});
  ASSERT_TRUE(fixed) << fixed.error();
  EXPECT_TRUE(fixed->drift_corrected);
  EXPECT_NEAR(fixed->asymmetry->asymmetry_ppm, 0.0, 1e-4);
  EXPECT_TRUE(fixed->asymmetry->judged);
  const double k_at_tc = kK * (1 + kTc * 1e-6 * (tc_c - 25.0));
  EXPECT_NEAR(fixed->sf_pulse_per_arcsec / k_at_tc - 1, 0.0, 1e-12);

  // TC's own error is carried: d(asymmetry)/d(TC) is -0.5 C here, so an SE of 1 ppm/C adds
  // 0.5 ppm in quadrature to the points' share.
  const auto carried = sc::analyze_rate_ladder(pts, sc::LadderTemperatureModel{kTc, 1.0});
  ASSERT_TRUE(carried);
  const double points_share = fixed->asymmetry->asymmetry_se_ppm;
  EXPECT_NEAR(carried->asymmetry->asymmetry_se_ppm, std::hypot(points_share, 0.5), 0.02);
}

TEST(ScaleFactor, ASteadyLadderIsJudgedWithoutATemperatureCoefficient) {
  auto pts = ladder(TrueGyro{}, nullptr);
  for (auto& p : pts) p.temp_c = 25.0 + 0.01 * (&p - pts.data()) / 11.0;  // 0.01 C spread
  const auto r = sc::analyze_rate_ladder(pts);
  ASSERT_TRUE(r);
  EXPECT_LE(r->drift_c, sc::kMaxUncorrectedDriftC);
  EXPECT_TRUE(r->asymmetry->judged);
  // A point without a temperature: the drift is not known, nothing is flagged or corrected.
  pts[3].temp_c = std::numeric_limits<double>::quiet_NaN();
  const auto unknown = sc::analyze_rate_ladder(pts, sc::LadderTemperatureModel{4.0, 0.1});
  ASSERT_TRUE(unknown);
  EXPECT_TRUE(std::isnan(unknown->temp_c));
  EXPECT_FALSE(unknown->drift_corrected);
  EXPECT_TRUE(unknown->asymmetry->judged);
}
