// The report's figure data (station/report/report_data, report_allan): what each figure draws,
// checked against the model it comes from.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "station/report/report_allan.hpp"
#include "station/report/report_data.hpp"

namespace {

namespace sc = station::compensation;
namespace rp = station::report;
using station::SampleRow;

constexpr double kB0 = 0.02, kK1 = 4e-4, kK0 = 0.03, kRef = 25.0, kEarth = 9.7;

/// The paper's model B = B0 + k1 dT + k0 gradT with known coefficients (no fitting).
sc::FitResult known_fit() {
  sc::FitResult f;
  f.spec = sc::ModelSpec{{sc::Term::dT, sc::Term::gradT}, kRef};
  f.names = {"B0", "k1", "k0"};
  f.coefficients = {kB0, kK1, kK0};
  f.std_errors = {1e-4, 1e-6, 1e-3};
  return f;
}

/// n bins: temperature from -40 C up, gradient growing, bias = model + a known wiggle.
sc::ModelData bins_data(std::size_t n) {
  sc::ModelData d;
  for (std::size_t i = 0; i < n; ++i) {
    const double temp = -40.0 + 110.0 * static_cast<double>(i) / static_cast<double>(n);
    const double grad = 0.2 + 0.01 * static_cast<double>(i % 7);
    d.temp_c.push_back(temp);
    d.grad_c.push_back(grad);
    d.bias_dph.push_back(kB0 + kK1 * (temp - kRef) + kK0 * grad + 1e-4 * std::sin(i));
    d.dtdt_c_per_h.push_back(10.0);
    d.channel.push_back(0.0);
    d.t_mid_s.push_back(600.0 * static_cast<double>(i));
  }
  return d;
}

/// 1 Hz samples over `seconds`: temperature heating at `c_per_h`, recording from `record_from_s`.
std::vector<SampleRow> samples(double seconds, double c_per_h, double record_from_s,
                               double noise_dph, unsigned seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_dph);
  std::vector<SampleRow> rows;
  for (double t = 0; t < seconds; t += 1.0) {
    SampleRow s;
    s.t_s = t;
    const double temp = -40.0 + c_per_h * t / 3600.0, grad = 0.3;
    s.temp_c = temp;
    s.temp2_c = temp + grad;
    s.air_c = temp + 1.0;
    s.rate_dph = kEarth + kB0 + kK1 * (temp - kRef) + kK0 * grad + noise(rng);
    s.recording = t >= record_from_s;
    rows.push_back(s);
  }
  return rows;
}

TEST(ReportData, WholeRunBinsCoverTheRunNotOnlyTheRecordWindowAndRemoveEarthRate) {
  auto rows = samples(6000.0, 10.0, 3000.0, 0.0);  // 10 bins, half of them before recording
  rows[100].flags = station::kSafeHold;            // left out, as bin_run does
  rows[101].air_c.reset();                         // a chamber reading missed: mean of the rest
  const auto bins = rp::whole_run_bins(rows, 600.0, kEarth);
  ASSERT_EQ(bins.size(), 10u);
  for (const auto& b : bins) {
    // The bin mean of a linear series is its value at the mean time; rounding only.
    EXPECT_NEAR(b.bias_dph, kB0 + kK1 * (b.temp_c - kRef) + kK0 * 0.3, 1e-12);
    EXPECT_NEAR(b.air_c, b.temp_c + 1.0, 1e-3);  // air over all samples, temp over the usable
    EXPECT_NEAR(b.dtdt_c_per_h, 10.0, 1e-9);
  }
  const auto f = rp::figure_2a(bins, 600.0);
  EXPECT_EQ(f.id, "2a");
  EXPECT_EQ(f.points(), 3 * bins.size());
  EXPECT_NEAR(f.series[0].x[0], bins[0].t_mid_s / 3600.0, 1e-12);
  EXPECT_TRUE(f.series[1].second_y && f.series[2].second_y && !f.series[0].second_y);
}

TEST(ReportData, Figure2bSplitsHeatingCoolingAndSteadyBinsBySlope) {
  std::vector<rp::RunBin> bins{{0, 0.1, 20, 21, 5.0},
                               {600, 0.2, 25, 26, 10.0},
                               {1200, 0.3, 30, 29, -8.0},
                               {1800, 0.4, 30, 30, 0.5}};
  const auto f = rp::figure_2b(bins);
  ASSERT_EQ(f.series.size(), 3u);
  EXPECT_EQ(f.series[0].y.size(), 2u);  // heating
  EXPECT_EQ(f.series[1].y.size(), 1u);  // cooling
  EXPECT_EQ(f.series[2].y.size(), 1u);  // steady: |dT/dt| <= 1 C/h
  EXPECT_EQ(f.points(), 4u);
  EXPECT_DOUBLE_EQ(f.series[1].x[0], 30.0);
  EXPECT_DOUBLE_EQ(f.series[1].y[0], 0.3);
}

TEST(ReportData, Figure3WithoutRampRunsHasNoPointsAndSaysWhy) {
  const auto none = rp::figure_3({});
  EXPECT_EQ(none.points(), 0u);
  EXPECT_NE(none.note.find("ramp_10"), std::string::npos);
  const auto two = rp::figure_3({{"ramp_00", 3, bins_data(20)}, {"ramp_10", 4, bins_data(66)}});
  EXPECT_EQ(two.points(), 86u);
  ASSERT_EQ(two.series.size(), 2u);
  EXPECT_EQ(two.series[1].label, "ramp_10 (run 4)");
  EXPECT_NE(two.note.find("ramp_20"), std::string::npos);  // the missing one is named
  EXPECT_EQ(rp::figure_3({{"ramp_00", 1, bins_data(5)},
                          {"ramp_10", 2, bins_data(5)},
                          {"ramp_20", 3, bins_data(5)}})
                .note,
            "");
}

TEST(ReportData, Figure4IsBiasMinusTheTemperatureTermsAgainstTheGradientWithTheK0Line) {
  const auto d = bins_data(66);
  const auto f = rp::figure_4(known_fit(), d);
  ASSERT_EQ(f.series.size(), 2u);
  EXPECT_EQ(f.points(), 2 * d.bias_dph.size());
  for (std::size_t i = 0; i < d.bias_dph.size(); ++i) {
    // y = bias - k1 dT exactly (values ~0.1 deg/h: a few ulp of rounding).
    EXPECT_NEAR(f.series[0].y[i], d.bias_dph[i] - kK1 * (d.temp_c[i] - kRef), 1e-15);
    EXPECT_DOUBLE_EQ(f.series[0].x[i], d.grad_c[i]);
    EXPECT_NEAR(f.series[1].y[i], kB0 + kK0 * d.grad_c[i], 1e-15);
    // What is left beside the line is only the wiggle the model does not hold.
    EXPECT_NEAR(f.series[0].y[i] - f.series[1].y[i], 1e-4 * std::sin(i), 1e-15);
  }
  auto no_k0 = known_fit();
  no_k0.spec.terms = {sc::Term::dT};
  no_k0.names = {"B0", "k1"};
  no_k0.coefficients = {kB0, kK1};
  const auto g = rp::figure_4(no_k0, d);
  EXPECT_EQ(g.series.size(), 1u);
  EXPECT_FALSE(g.note.empty());
}

TEST(ReportData, Figure5aBeforeAfterTemperatureOnlyAndAfterTheWholeModel) {
  const auto d = bins_data(66);
  const auto fit = known_fit();
  const auto f = rp::figure_5a(fit, d);
  ASSERT_EQ(f.series.size(), 3u);
  EXPECT_EQ(f.points(), 3 * d.bias_dph.size());
  const auto model = sc::predict(fit, d.view());
  for (std::size_t i = 0; i < d.bias_dph.size(); ++i) {
    EXPECT_DOUBLE_EQ(f.series[0].y[i], d.bias_dph[i]);
    EXPECT_NEAR(f.series[1].y[i], d.bias_dph[i] - kB0 - kK1 * (d.temp_c[i] - kRef), 1e-15);
    EXPECT_NEAR(f.series[2].y[i], d.bias_dph[i] - model[i], 1e-15);
    EXPECT_NEAR(f.series[2].y[i], 1e-4 * std::sin(i), 1e-15);  // bias - B(x): the wiggle
    EXPECT_DOUBLE_EQ(f.series[2].x[i], d.temp_c[i]);
  }
}

TEST(ReportData, ModelPartKeepsOnlyTheNamedCoefficients) {
  const auto d = bins_data(10);
  const auto k1 = rp::model_part(known_fit(), d.view(), {"k1"});
  for (std::size_t i = 0; i < k1.size(); ++i) EXPECT_NEAR(k1[i], kK1 * (d.temp_c[i] - kRef), 1e-16);
  auto cubic = known_fit();
  cubic.names = {"B0", "k1", "k2", "k0"};
  EXPECT_EQ(rp::temperature_terms(cubic), (std::vector<std::string>{"k1", "k2"}));
}

TEST(ReportData, OneHzRecordIsTheRecordWindowWithTheModelRemovedPerSample) {
  auto rows = samples(4000.0, 10.0, 1000.0, 0.0);
  rows[2000].rate_dph.reset();  // a lost latch: no sample
  rows[2001].flags = station::kBoardFault;
  const auto r = rp::one_hz_record(rows, kEarth, known_fit(), 600.0);
  ASSERT_EQ(r.bias_dph.size(), 3000u - 2u);
  ASSERT_EQ(r.compensated_dph.size(), r.bias_dph.size());
  for (std::size_t i = 0; i < r.bias_dph.size(); ++i) {
    // rate = Earth + model exactly: bias - B(T, T2 - T) is rounding of ~10 deg/h values.
    EXPECT_NEAR(r.compensated_dph[i], 0.0, 1e-13);
  }
}

TEST(ReportData, AllanCurvesOfWhiteNoiseAfterCompensationReadTheNoise) {
  constexpr double kSigmaDph = 0.005;
  const auto rows = samples(40000.0, 10.0, 0.0, kSigmaDph, 7);
  const auto c = rp::allan_curves(rp::one_hz_record(rows, kEarth, known_fit(), 600.0));
  ASSERT_FALSE(c.after.empty());
  ASSERT_EQ(c.before.size(), c.after.size());
  // White rate noise: sigma(tau = 1 s) = sigma of one sample; the overlapping estimate over
  // N = 40000 has a relative spread ~ 1/sqrt(2 N) = 0.0035 (NIST SP 1065 eq. 5.2 edf): 5 of them.
  EXPECT_NEAR(c.after[0].adev / kSigmaDph, 1.0, 5 * 0.0035);
  EXPECT_LE(c.after[0].ci_low, c.after[0].adev);
  EXPECT_GE(c.after[0].ci_high, c.after[0].adev);
  // Before compensation the thermal drift (k1 * 10 C/h) dominates the long taus.
  EXPECT_GT(c.before.back().adev, 10 * c.after.back().adev);
  const auto f = rp::figure_5b(c);
  EXPECT_TRUE(f.log_axes);
  // The two measured curves and the two curves of the fitted IEEE 952 terms.
  ASSERT_EQ(f.series.size(), 4u);
  EXPECT_EQ(f.points(), 4 * c.before.size());
  EXPECT_EQ(f.series[1].y_low.size(), c.after.size());
  EXPECT_EQ(f.series[3].label, "fitted terms (after)");
  // White noise of sigma per 1 s sample is an angle random walk N = sigma / 60 deg/sqrt(h): the
  // fitted term finds it within 3 of its standard errors.
  ASSERT_TRUE(c.noise_after.angle_random_walk_deg_rth && c.noise_after.angle_random_walk_se);
  EXPECT_NEAR(*c.noise_after.angle_random_walk_deg_rth, kSigmaDph / 60,
              3 * *c.noise_after.angle_random_walk_se);
  EXPECT_TRUE(f.note.empty());
  EXPECT_EQ(rp::figure_5b(rp::allan_curves({})).points(), 0u);
}

}  // namespace
