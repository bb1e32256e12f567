// The report's acceptance pages (station/report/report_acceptance*): each figure checked against
// the maths it draws (compensation/scale_factor, turn_on, positions), the reason shown where a
// figure was not computed, and the pages served by name from a simulated acceptance run.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "compensation/earth_rate.hpp"
#include "station/report/report_acceptance.hpp"
#include "station/report/report_html.hpp"
#include "station/report/report_page.hpp"
#include "station/report/report_pages.hpp"
#include "station/sim/sim_run.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace sc = station::compensation;
namespace rp = station::report;
using station::LadderFigures;
using station::SerialAcceptance;

/// A ladder at `temp_c` whose scale factor is `k` with standard error `se` (and one residual).
LadderFigures ladder(double temp_c, double k, double se) {
  sc::LadderResult r;
  r.sf_pulse_per_arcsec = k;
  r.sf_se_pulse_per_arcsec = se;
  r.residuals = {{-100.0, 1.5}, {100.0, -1.5}};
  LadderFigures l;
  l.label = "plateau";
  l.temp_c = temp_c;
  l.fit = r;
  return l;
}

/// Three plateaus that scatter about a line (chi2/dof > 1: the SEs are scaled), fitted by the
/// station's own temperature fit.
SerialAcceptance three_plateaus() {
  SerialAcceptance a;
  a.serial = "SN1";
  a.ladders = {ladder(-40.0, 0.66660, 2e-6), ladder(25.0, 0.66668, 1e-6),
               ladder(70.0, 0.66671, 3e-6)};
  std::vector<sc::PlateauScaleFactor> p;
  for (const auto& l : a.ladders)
    p.push_back({l.temp_c, l.fit->sf_pulse_per_arcsec, l.fit->sf_se_pulse_per_arcsec});
  a.sf_vs_temp = sc::fit_scale_factor_vs_temperature(p, 25.0);
  return a;
}

// The band's half-width is the line's own standard error: at T_ref it is SE(K0), and its second
// difference in T is 2 SE(s)^2 (var(K0 + s d) = var K0 + 2 d cov + d^2 var s).
TEST(ReportAcceptance, TheTemperatureBandIsTheFitsOwnCovariance) {
  const auto a = three_plateaus();
  ASSERT_TRUE(a.sf_vs_temp && *a.sf_vs_temp) << a.sf_vs_temp->error();
  const auto& t = a.sf_vs_temp->value();
  ASSERT_GT(t.se_scale, 1.0);  // the scaled case: the band must carry it
  const double se0 = rp::sf_line_se(a.ladders, t, 25.0);
  EXPECT_NEAR(se0, t.sf_ref_se_pulse_per_arcsec, 1e-9 * se0);
  const double vp = std::pow(rp::sf_line_se(a.ladders, t, 26.0), 2);
  const double vm = std::pow(rp::sf_line_se(a.ladders, t, 24.0), 2);
  const double var_s = (vp + vm - 2 * se0 * se0) / 2;
  EXPECT_NEAR(std::sqrt(var_s), t.slope_se_pulse_per_arcsec_per_c,
              1e-6 * t.slope_se_pulse_per_arcsec_per_c);
}

TEST(ReportAcceptance, TheTemperatureFigureIsPpmOfKAtTheReferenceWithWhiskersAndTheLine) {
  const auto a = three_plateaus();
  const auto f = rp::sf_temperature_figure("S2.1", a);
  const auto& t = a.sf_vs_temp->value();
  ASSERT_EQ(f.series.size(), 2u);
  const auto& pts = f.series[0];
  ASSERT_EQ(pts.y.size(), 3u);
  EXPECT_TRUE(pts.whiskers);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& k = a.ladders[i].fit.value();
    const double ppm = 1e6 / t.sf_ref_pulse_per_arcsec;
    EXPECT_NEAR(pts.y[i], (k.sf_pulse_per_arcsec - t.sf_ref_pulse_per_arcsec) * ppm, 1e-9);
    EXPECT_NEAR(pts.y_high[i] - pts.y[i], k.sf_se_pulse_per_arcsec * ppm, 1e-9);
  }
  const auto& line = f.series[1];
  EXPECT_TRUE(line.line);
  EXPECT_DOUBLE_EQ(line.x.front(), -40.0);
  EXPECT_DOUBLE_EQ(line.x.back(), 70.0);
  for (std::size_t i = 0; i < line.x.size(); ++i)
    EXPECT_NEAR(line.y[i], t.tc_ppm_per_c * (line.x[i] - 25.0), 1e-9);
  EXPECT_TRUE(f.note.empty()) << f.note;
}

TEST(ReportAcceptance, ANotComputedFigureHasNoPointsAndSaysWhy) {
  SerialAcceptance a;
  a.serial = "SN1";
  a.ladders = {ladder(25.0, 0.6667, 1e-6)};
  a.ladders.push_back(LadderFigures{});
  a.ladders.back().label = "cold";
  a.ladders.back().step_index = 6;
  a.ladders.back().temp_c = -40.0;
  a.ladders.back().fit = sc::NotComputed{"2 points in tolerance, a ladder needs 3"};
  const auto sf = rp::sf_temperature_figure("S2.1", a);  // one plateau: no temperature fit
  EXPECT_EQ(sf.points(), 0u);
  EXPECT_NE(sf.note.find("plateaus at two temperatures"), std::string::npos) << sf.note;
  const auto res = rp::ladder_residuals_figure("S1.1", a);
  EXPECT_EQ(res.points(), 2u);
  EXPECT_NE(res.note.find("cold (step 7, -40.0 \u00b0C): 2 points in tolerance, a ladder needs 3"),
            std::string::npos)
      << res.note;
  a.turn_on = sc::Computed<sc::TurnOnResult>(sc::NotComputed{"turn-on 0: too short"});
  for (const auto& f : {rp::turn_on_figure("T1.1", a), rp::warmup_figure("T2.1", {a, {}, {}})}) {
    EXPECT_EQ(f.points(), 0u);
    EXPECT_EQ(f.note, "Not computed: turn-on 0: too short");
  }
  // The page hides the chart of a figure with no points, and its note stays.
  EXPECT_NE(rp::figure_html(sf).find("data-points=\"0\""), std::string::npos);
}

/// Two turn-ons settling exponentially onto their final values (b = f + A e^(-t/tau)).
struct TurnOns {
  std::vector<std::vector<double>> t, b;
  sc::TurnOnWindows w;
};
TurnOns settling() {
  TurnOns s;
  for (const double f : {0.01, 0.03}) {
    s.t.emplace_back();
    s.b.emplace_back();
    for (double t = 30; t < 900; t += 60) {
      s.t.back().push_back(t);
      s.b.back().push_back(f + 0.2 * std::exp(-t / 150.0) + 0.001 * std::sin(t));
    }
  }
  s.w = {450, 900, 600, 900, 0.01, 0.95};
  return s;
}

TEST(ReportAcceptance, WarmupCurvesAreBiasLessTheFinalValueWithTheBandAndAgreeWithTheAnalysis) {
  auto s = settling();
  std::vector<sc::TurnOnSeries> series;
  for (std::size_t k = 0; k < 2; ++k) series.push_back({s.t[k], s.b[k]});
  rp::SerialAcceptanceReport r;
  r.figures.serial = "SN1";
  r.figures.turn_on = sc::analyze_turn_ons(series, s.w);
  ASSERT_TRUE(*r.figures.turn_on) << r.figures.turn_on->error();
  r.figures.turn_on_band_dph = s.w.band_dph;
  for (std::size_t k = 0; k < 2; ++k) r.warmups.push_back({s.t[k], s.b[k]});
  const auto f = rp::warmup_figure("T2.1", r);
  ASSERT_EQ(f.series.size(), 3u) << f.note;
  const auto& res = r.figures.turn_on->value();
  for (std::size_t k = 0; k < 2; ++k) {
    ASSERT_TRUE(res.turn_ons[k].warmup_s);
    EXPECT_NE(f.series[k].label.find(fmt::format("{:.0f} s", *res.turn_ons[k].warmup_s)),
              std::string::npos);
    for (std::size_t j = 0; j < s.t[k].size(); ++j)
      EXPECT_DOUBLE_EQ(f.series[k].y[j], s.b[k][j] - res.turn_ons[k].final_dph);
  }
  EXPECT_EQ(f.series[2].x, (std::vector<double>{0.0, 870.0 + station::kTurnOnBinS / 2}));
  EXPECT_EQ(f.series[2].y_high, (std::vector<double>{0.01, 0.01}));
  EXPECT_EQ(f.series[2].y_low, (std::vector<double>{-0.01, -0.01}));
  // Curves that are not the analysis' bins are not drawn as if they were.
  r.warmups[1].bias_dph[r.warmups[1].bias_dph.size() - 2] += 1.0;  // outside the band, late
  const auto off = rp::warmup_figure("T2.1", r);
  EXPECT_EQ(off.points(), 0u);
  EXPECT_NE(off.note.find("turn-on 2"), std::string::npos) << off.note;
}

TEST(ReportAcceptance, TurnOnBiasesHaveTheirErrorsAndTheBandIsMeanPlusMinusSigma) {
  auto s = settling();
  std::vector<sc::TurnOnSeries> series;
  for (std::size_t k = 0; k < 2; ++k) series.push_back({s.t[k], s.b[k]});
  SerialAcceptance a;
  a.turn_on = sc::analyze_turn_ons(series, s.w);
  const auto f = rp::turn_on_figure("T1.1", a);
  const auto& rep = a.turn_on->value().repeatability;
  ASSERT_EQ(f.series.size(), 2u);
  EXPECT_TRUE(f.series[0].whiskers);
  EXPECT_EQ(f.series[0].x, (std::vector<double>{1, 2}));
  EXPECT_DOUBLE_EQ(f.series[1].y_high[0] - f.series[1].y[0], rep.repeatability_dph);
  EXPECT_DOUBLE_EQ(f.series[1].y[1], rep.mean_bias_dph);
}

// The points are the measured outputs less the fitted bias at the angles the fit took; the curve
// is the fitted sinusoid, through them to the residual.
TEST(ReportAcceptance, PositionsArePointsLessTheBiasOnTheFittedSinusoid) {
  const std::vector<double> angles{0, 45, 90, 180, 270};
  const double lat = 40.0, omega = sc::kEarthRateDph, tilt = 2e-3, dir = 30.0, bias = 0.05;
  std::vector<sc::PositionPoint> pts;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double rad = std::numbers::pi / 180.0;
    const double y =
        bias + omega * std::sin(lat * rad) * std::cos(tilt) +
        omega * std::cos(lat * rad) * std::sin(tilt) * std::cos((angles[i] + dir) * rad) +
        0.002 * (i % 2 ? 1 : -1);
    pts.push_back({angles[i], y, 0.002});
  }
  rp::SerialAcceptanceReport r;
  r.figures.serial = "SN1";
  r.figures.positions.emplace_back();
  r.figures.positions[0].label = "room";
  r.figures.positions[0].fit = sc::analyze_positions_axis_vertical(pts, {lat, 0.0});
  ASSERT_TRUE(r.figures.positions[0].fit) << r.figures.positions[0].fit.error();
  r.position_angles_deg = {angles};
  const auto f = rp::positions_figure("P1.1", r);
  ASSERT_EQ(f.series.size(), 2u) << f.note;
  const auto& v = r.figures.positions[0].fit.value();
  const auto& measured = f.series[1];
  for (std::size_t i = 0; i < angles.size(); ++i)
    EXPECT_NEAR(measured.y[i], pts[i].output_dph - v.bias_dph, 1e-12);
  const auto& curve = f.series[0];
  EXPECT_EQ(curve.x.front(), 0.0);
  EXPECT_EQ(curve.x.back(), 360.0);
  EXPECT_NEAR(curve.y[0], measured.y[0] - v.fit.residuals_dph[0], 1e-12);  // at 0 deg
  // Angles that do not match the fit's positions: no points, and why.
  r.position_angles_deg = {{0, 90}};
  const auto none = rp::positions_figure("P1.1", r);
  EXPECT_EQ(none.points(), 0u);
  EXPECT_NE(none.note.find("could not be matched"), std::string::npos) << none.note;
}

// A short acceptance run on the simulated rig: its three pages served by name (GET /reports/NAME
// renders through report_page), a figure per serial on each; a name of no page is none.
TEST(ReportAcceptance, TheRunsPagesAreServedByNameWithTheirFigures) {
  station::SimRunOptions o;
  o.db_path = station::testing_support::fresh_db("report_acceptance");
  o.protocol = std::string(STATION_SOURCE_DIR) + "/tests/report/acceptance_two_plateaus.toml";
  o.progress = false;
  o.fresh = true;
  o.gyros = 2;
  const auto out = station::run_simulated(o);
  ASSERT_EQ(out["state"], "completed") << out.dump();
  station::Store store(o.db_path, station::OpenMode::read_only);
  const auto index = rp::report_page(store, "run-1.html", "");
  ASSERT_TRUE(index);
  for (const char* kind : {"scale-factor", "turn-on", "positions"}) {
    const std::string name = std::string("run-1-") + kind + ".html";
    EXPECT_NE(index->find("href=\"" + name + "\""), std::string::npos) << name;
    const auto page = rp::report_page(store, name, "");
    ASSERT_TRUE(page) << name;
    EXPECT_NE(page->find("data-figure=\""), std::string::npos);
    EXPECT_NE(page->find("SIM-0002"), std::string::npos);
  }
  EXPECT_NE(rp::report_page(store, "run-1-positions.html", "")->find("Fig. P1.2"),
            std::string::npos);
  // Two power_cycles steps (room, warm): each with its heading, table and figures T1.n.j, T2.n.j.
  const auto turn_on = *rp::report_page(store, "run-1-turn-on.html", "");
  for (const char* id : {"Fig. T1.2.1", "Fig. T2.2.1", "Fig. T1.2.2", "Fig. T2.2.2"})
    EXPECT_NE(turn_on.find(id), std::string::npos) << id;
  EXPECT_EQ(turn_on.find("Fig. T1.2:"), std::string::npos);  // no unnumbered step
  EXPECT_NE(turn_on.find("<h3 class=\"turn-on-step\">turn-ons, room (step 2, "), std::string::npos);
  EXPECT_NE(turn_on.find("<h3 class=\"turn-on-step\">turn-ons, warm (step 11, "),
            std::string::npos);
  EXPECT_FALSE(rp::report_page(store, "run-1-warmup.html", ""));
}

}  // namespace
