// A report is a record of its run (issue 35): the run's own fit with its own model, later fits
// and releases as dated notes; the run's bin width read, not written; Fig. 5b's fitted curves
// in the data dygraphs draws; the noise table's words; `station verify` reporting a stored
// verification instead of storing a copy.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "station/release/verification.hpp"
#include "station/report/report.hpp"
#include "station/report/report_html.hpp"
#include "station/report/report_model.hpp"
#include "tests/station/release_fixture.hpp"
#include "tests/station/rig_process.hpp"

namespace {

namespace rp = station::report;
namespace ts = station::testing_support;
using nlohmann::json;

/// `station ARGS`: its exit status and stdout (stderr dropped).
std::pair<int, std::string> station_stdout(const std::string& args) {
  FILE* p = popen((ts::kStationBin + " " + args + " 2>/dev/null").c_str(), "r");
  std::string out;
  if (p == nullptr) return {-1, out};
  char buf[4096];
  for (std::size_t n = 0; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  const int raw = pclose(p);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, out};
}

station::compensation::FitResult fit_named(std::vector<std::string> names) {
  station::compensation::FitResult f;
  f.names = std::move(names);
  f.coefficients.assign(f.names.size(), 0.001);
  f.std_errors.assign(f.names.size(), 0.0001);
  return f;
}

TEST(ReportRecord, TheModelLineIsBuiltFromTheFitsOwnTerms) {
  EXPECT_EQ(rp::model_formula(fit_named({"B0", "k1", "k0"})),
            "B = B0 + k1\u00b7\u0394T + k0\u00b7\u2207T");  // the paper's eq. (4)
  EXPECT_EQ(rp::model_formula(fit_named({"B0", "k1", "k2", "k3"})),
            "B = B0 + k1\u00b7\u0394T + k2\u00b7\u0394T\u00b2 + k3\u00b7\u0394T\u00b3");
  EXPECT_EQ(rp::model_formula(fit_named({"B0"})), "B = B0");
}

/// The part of a serial page that is the run's own fit: from the model line to the noise terms.
std::string own_fit_part(const std::string& page) {
  const auto from = page.find("<p class=\"model\">");
  const auto to = page.find("<h2>Noise terms");
  if (from == std::string::npos || to == std::string::npos) return "";
  return page.substr(from, to - from);
}

std::string report_page(const std::string& db, std::int64_t run, const std::string& dir) {
  std::filesystem::remove_all(dir);
  rp::ReportOptions o;
  o.db = db;
  o.out_dir = dir;
  o.run_id = run;
  const auto files = rp::write_report(o);
  EXPECT_EQ(files.pages.size(), 1u);
  return files.pages.empty() ? "" : ts::slurp(files.pages[0]);
}

// Run 1's report after a cubic fit of run 1 is made and released: the same fit, model and
// coefficients as before (the run's own), and the cubic fit and its release as dated notes, each
// with its own model.
TEST(ReportRecord, ALaterReleasedCubicFitIsANoteNotTheRunsFit) {
  const auto c = ts::calibrated_db("report-record", 1);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const std::string dir = ::testing::TempDir() + "report-record-" + std::to_string(getpid());
  const std::string before = report_page(c.path, c.calibration_run, dir + "-a");
  const std::string own = own_fit_part(before);
  ASSERT_FALSE(own.empty()) << before.substr(0, 2000);
  EXPECT_NE(own.find("model B = B0 + k1\u00b7\u0394T + k0\u00b7\u2207T"), std::string::npos) << own;
  const auto [rc, fit_out] =
      station_stdout("fit --db " + c.path + " --serial " + sn + " --runs " +
                     std::to_string(c.calibration_run) + " --terms dT,dT2,dT3 --json");
  ASSERT_EQ(rc, 0) << fit_out;
  const auto cubic = json::parse(fit_out)["fit_id"].get<std::int64_t>();
  const auto [rel_rc, rel_out] =
      station_stdout("release --db " + c.path + " --fit " + std::to_string(cubic) + " --by tester");
  ASSERT_EQ(rel_rc, 0) << rel_out;
  const std::string after = report_page(c.path, c.calibration_run, dir + "-b");
  EXPECT_EQ(own_fit_part(after), own) << "the run's own fit changed after a later fit";
  const std::string cubic_model =
      "model B = B0 + k1\u00b7\u0394T + k2\u00b7\u0394T\u00b2 + k3\u00b7\u0394T\u00b3";
  const auto note = after.find("<li data-fit=\"" + std::to_string(cubic) + "\">");
  ASSERT_NE(note, std::string::npos) << "no dated note of the later fit";
  const std::string li = after.substr(note, after.find("</li>", note) - note);
  EXPECT_NE(li.find(cubic_model), std::string::npos) << li;
  EXPECT_NE(li.find("released"), std::string::npos) << li;
  // The release paragraph names the released calibration with its model.
  const auto rel = after.find("<p class=\"release\">");
  ASSERT_NE(rel, std::string::npos);
  const std::string release = after.substr(rel, after.find("</p>", rel) - rel);
  EXPECT_NE(release.find("fit " + std::to_string(cubic) + " released"), std::string::npos)
      << release;
  EXPECT_NE(release.find(cubic_model), std::string::npos) << release;
}

TEST(ReportRecord, Figure2aNamesTheRunsBinWidth) {
  std::vector<rp::RunBin> bins{{30, 0.1, 20, 21, 5.0}, {90, 0.2, 21, 22, 5.0}};
  EXPECT_EQ(rp::figure_2a(bins, 60.0).title, "Bias (60 s bins) and temperatures against time");
  EXPECT_EQ(rp::figure_2a(bins, 600.0).title, "Bias (600 s bins) and temperatures against time");
}

// Dygraphs with customBars reads every value as [low, y, high]: a plain number is not drawn.
TEST(ReportRecord, ASeriesWithoutIntervalInABarsFigureIsItsValueThrice) {
  auto f = rp::make_figure("5b", "t", "tau", "adev");
  rp::Series with, fitted;
  with.label = "before";
  with.x = {1, 2};
  with.y = {0.5, 0.4};
  with.y_low = {0.45, 0.3};
  with.y_high = {0.55, 0.5};
  fitted.label = "fitted terms (before)";
  fitted.x = {1, 2};
  fitted.y = {0.52, 0.38};
  f.series = {with, fitted};
  const json j = rp::figure_json(f);
  EXPECT_EQ(j["rows"], json::parse("[[1,[0.45,0.5,0.55],[0.52,0.52,0.52]],"
                                   "[2,[0.3,0.4,0.5],[0.38,0.38,0.38]]]"));
}

rp::RunReport noise_report(std::optional<double> chi2_before, std::optional<double> chi2_after) {
  rp::RunReport r;
  r.run.id = 1;
  rp::SerialReport s;
  s.slot.serial = "SN1";
  s.fit = station::FitRecord{};
  s.fit->fit = fit_named({"B0", "k1"});
  s.allan.noise_before.angle_random_walk_deg_rth = 0.01;
  s.allan.noise_before.angle_random_walk_se = 0.001;
  s.allan.noise_before.fit_chi2_per_dof = chi2_before;
  s.allan.noise_after.angle_random_walk_deg_rth = 0.009;
  s.allan.noise_after.fit_chi2_per_dof = chi2_after;
  r.serials = {s};
  return r;
}

// A term the fit left out is "not in fit", not the value 0; a χ²/dof far above 1 is explained
// with the factor the uncertainties were widened by (compensation/allan.hpp: se × √(χ²/dof)).
TEST(ReportRecord, TheNoiseTableSaysNotInFitAndWhatAChi2FarAbove1Means) {
  const auto r = noise_report(556.0, 1.2);
  const auto page = rp::serial_html(r, r.serials[0], rp::Assets{});
  EXPECT_EQ(page.find("0 (not in fit)"), std::string::npos);
  EXPECT_NE(page.find("<td>not in fit</td>"), std::string::npos);
  const auto note = page.find("<p class=\"note chi2\" data-column=\"before\">");
  ASSERT_NE(note, std::string::npos) << "no word on a chi2/dof of 556";
  const std::string text = page.substr(note, page.find("</p>", note) - note);
  EXPECT_NE(text.find("556"), std::string::npos) << text;
  EXPECT_NE(text.find("do not describe"), std::string::npos) << text;
  EXPECT_NE(text.find("= 23.6"), std::string::npos) << text;  // sqrt(556) = 23.58
  EXPECT_EQ(page.find("data-column=\"after\""), std::string::npos) << "1.2 is about 1";
}

// Three calls of `station verify` on the same fit and run store one verification; --redo
// stores another.
TEST(ReportRecord, VerifyAgainReportsTheStoredVerificationUnlessRedo) {
  const auto c = ts::calibrated_db("verify-again", 1);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const auto count = [&] {
    station::Store store(c.path, station::OpenMode::read_only);
    return station::verifications_of_run(store, c.verification_run).size();
  };
  ASSERT_EQ(count(), 1u);  // run --sim --verify stored one
  const std::string args =
      "verify --db " + c.path + " --serial " + sn + " --run " + std::to_string(c.verification_run);
  std::int64_t id = 0;
  for (int call = 0; call < 3; ++call) {
    const auto [rc, out] = station_stdout(args + " --json");
    ASSERT_EQ(rc, 0) << out;
    const auto j = json::parse(out);
    EXPECT_TRUE(j.value("stored_before", false)) << j.dump();
    if (call == 0) id = j["verification_id"].get<std::int64_t>();
    EXPECT_EQ(j["verification_id"].get<std::int64_t>(), id);
  }
  const auto [rc_text, text] = station_stdout(args);
  EXPECT_NE(text.find("--redo"), std::string::npos) << text;
  EXPECT_EQ(count(), 1u) << "verify stored a copy";
  const auto [rc, out] = station_stdout(args + " --redo --json");
  ASSERT_EQ(rc, 0) << out;
  const auto j = json::parse(out);
  EXPECT_FALSE(j["stored_before"].get<bool>());
  EXPECT_GT(j["verification_id"].get<std::int64_t>(), id);
  EXPECT_EQ(count(), 2u);
  // The report shows identical copies once (Fig. 6, not 6.1 and 6.2), saying so.
  const std::string page =
      report_page(c.path, c.verification_run,
                  ::testing::TempDir() + "verify-again-" + std::to_string(getpid()));
  EXPECT_NE(page.find("data-figure=\"6\""), std::string::npos);
  EXPECT_EQ(page.find("data-figure=\"6.2\""), std::string::npos);
  EXPECT_NE(page.find("the same verification was stored before"), std::string::npos);
}

}  // namespace
