// The report's pages (station/report/report_html, report_pages) and `station report`'s errors:
// strings from the database escaped, figure data as dygraphs takes it, one-line exit-2 errors.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <limits>

#include "station/common/input_error.hpp"
#include "station/report/report.hpp"
#include "station/report/report_html.hpp"
#include "station/report/report_pages.hpp"
#include "station/store/store.hpp"
#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace rp = station::report;
namespace ts = station::testing_support;
using nlohmann::json;

rp::Series series(const std::string& label, std::vector<double> x, std::vector<double> y) {
  rp::Series s;
  s.label = label;
  s.x = std::move(x);
  s.y = std::move(y);
  return s;
}

const std::string kHostile = "</script><script>alert('x')</script>&\"<!--";

TEST(ReportHtml, EscapesEveryMarkupCharacter) {
  EXPECT_EQ(rp::html_escape("a<b>&\"'c"), "a&lt;b&gt;&amp;&quot;&#39;c");
  const std::string s = rp::script_json(json{{"serial", kHostile}});
  EXPECT_EQ(s.find('<'), std::string::npos) << s;
  EXPECT_EQ(s.find('>'), std::string::npos) << s;
  EXPECT_EQ(json::parse(s)["serial"], kHostile);  // the same string once parsed
  // Invalid UTF-8 from a database column is replaced, not thrown on.
  EXPECT_NO_THROW(rp::script_json(json{{"x", std::string("\xff\xfe")}}));
}

TEST(ReportHtml, FigureRowsAreSortedByXWithNullWhereASeriesHasNoPoint) {
  auto f = rp::make_figure("2b", "t", "x", "y");
  f.series = {series("a", {3, 1, 3}, {30, 10, 31}), series("b", {2, 3}, {20, std::nan("")})};
  const json j = rp::figure_json(f);
  EXPECT_EQ(j["id"], "2b");
  EXPECT_EQ(j["points"], 4);
  // The repeated x = 3 of series a is a second row: every counted point is drawn.
  EXPECT_EQ(j["rows"], json::parse("[[1,10,null],[2,null,20],[3,30,null],[3,31,null]]"));
  EXPECT_EQ(j["options"]["labels"], json::parse(R"(["x","a","b"])"));
  EXPECT_EQ(j["options"]["series"]["a"]["strokeWidth"], 0.0);  // points only
  EXPECT_FALSE(j["options"]["customBars"].get<bool>());
}

TEST(ReportHtml, ConfidenceIntervalsBecomeDygraphsCustomBarsOnLogAxes) {
  auto f = rp::make_figure("5b", "t", "tau", "adev");
  f.log_axes = true;
  auto s = series("before", {1, 2}, {0.5, 0.4});
  s.y_low = {0.45, 0.3};
  s.y_high = {0.55, 0.5};
  s.line = true;
  f.series = {s};
  const json j = rp::figure_json(f);
  EXPECT_EQ(j["rows"], json::parse("[[1,[0.45,0.5,0.55]],[2,[0.3,0.4,0.5]]]"));
  EXPECT_TRUE(j["options"]["customBars"].get<bool>());
  EXPECT_TRUE(j["options"]["logscale"].get<bool>());
  EXPECT_TRUE(j["options"]["axes"]["x"]["logscale"].get<bool>());
}

rp::RunReport hostile_report() {
  rp::RunReport r;
  r.run.id = 7;
  r.run.protocol_name = kHostile;
  r.run.operator_name = kHostile;
  r.run.station = "rig <1>";
  r.events.push_back({12.0, "warn", "seq", "door", kHostile, std::nullopt});
  rp::SerialReport s;
  s.slot.serial = kHostile;
  s.fit = station::FitRecord{};
  s.fit->fit.names = {"B0"};
  s.fit->fit.coefficients = {0.01};
  s.fit->fit.std_errors = {0.001};
  auto f = rp::make_figure("2a", kHostile, "x", "y");
  f.series = {series(kHostile, {1}, {2})};
  s.figures = {f};
  r.serials = {s};
  return r;
}

TEST(ReportHtml, StringsFromTheDatabaseNeverReachThePageUnescaped) {
  const auto r = hostile_report();
  const rp::Assets a{"/*js*/", "/*css*/"};
  for (const auto& page :
       {rp::serial_html(r, r.serials[0], a), rp::index_html(r, a, {"run-7-slot0-x.html"})}) {
    EXPECT_EQ(page.find("<script>alert"), std::string::npos);  // as text, or \u003c in JSON
    EXPECT_EQ(page.find("<!--"), std::string::npos);
    // Three scripts of ours (library, data, renderer), each closed once.
    std::size_t closes = 0;
    for (auto p = page.find("</script>"); p != std::string::npos; p = page.find("</script>", p + 1))
      ++closes;
    EXPECT_EQ(closes, 3u);
  }
  const auto page = rp::serial_html(r, r.serials[0], a);
  EXPECT_NE(page.find("data-figure=\"2a\" data-points=\"1\""), std::string::npos);
  EXPECT_NE(page.find("rig &lt;1&gt;"), std::string::npos);
}

TEST(ReportHtml, VerdictTextReadsThePartsShape) {
  EXPECT_EQ(rp::verdict_text({}), "no verdict (no part limits applied)");
  rp::FitExtras pass{std::nullopt, json{{"pass", true}, {"failed", json::array()}}};
  EXPECT_EQ(rp::verdict_text(pass), "PASS");
  rp::FitExtras fail{std::nullopt, json::parse(R"({"pass": false, "failed": [
      {"limit": "std_ratio_max", "value": 0.4, "bound": 0.2},
      {"limit": "k1_range", "value": 0.1, "bound": [0, 0.05]}]})")};
  EXPECT_EQ(rp::verdict_text(fail),
            "FAIL: std_ratio_max: 0.4 (bound 0.2); k1_range: 0.1 (bound [0,0.05])");
}

TEST(ReportHtml, TheCoefficientTableShowsTheHonestAndTheOlsUncertainty) {
  station::Store store(ts::fresh_db("report-extras"));
  auto r = hostile_report();
  auto& fit = r.serials[0].fit->fit;
  EXPECT_FALSE(rp::fit_extras(store, *r.serials[0].fit).std_errors_ols);  // none stored
  fit.std_errors = {0.00321};
  fit.std_errors_ols = {0.00123};
  r.serials[0].extras = rp::fit_extras(store, *r.serials[0].fit);
  ASSERT_TRUE(r.serials[0].extras.std_errors_ols);
  EXPECT_EQ(*r.serials[0].extras.std_errors_ols, std::vector<double>{0.00123});
  const auto page = rp::serial_html(r, r.serials[0], rp::Assets{});
  EXPECT_NE(page.find("<td>3.210e-03</td><td>1.230e-03</td>"), std::string::npos);
}

TEST(ReportHtml, AMissingChartingLibraryNamesThePathAndThePackage) {
  try {
    rp::read_dygraphs("/nonexistent/dygraphs");
    FAIL() << "no throw";
  } catch (const station::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/nonexistent/dygraphs/dygraph.min.js"), std::string::npos) << what;
    EXPECT_NE(what.find("libjs-dygraphs"), std::string::npos) << what;
  }
}

TEST(ReportHtml, FileNamesKeepOnlySafeCharacters) {
  EXPECT_EQ(rp::file_safe("RLG-12.a_b"), "RLG-12.a_b");
  EXPECT_EQ(rp::file_safe("../x y/\xc3\xa9"), ".._x_y___");
}

struct Outcome {
  int status = -1;
  std::string out;
};

Outcome station_cmd(const std::string& args, const std::string& env = "") {
  const std::string out = ::testing::TempDir() + "report-" + std::to_string(getpid()) + ".out";
  const int rc =
      std::system((env + " " + ts::kStationBin + " " + args + " >" + out + " 2>&1").c_str());
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, ts::slurp(out)};
}

void expect_one_line_exit_2(const Outcome& o, const std::string& needle) {
  EXPECT_EQ(o.status, 2) << o.out;
  EXPECT_EQ(std::count(o.out.begin(), o.out.end(), '\n'), 1) << o.out;
  EXPECT_NE(o.out.find(needle), std::string::npos) << o.out;
}

TEST(ReportCli, BadInputIsOneLineAndExit2) {
  const auto db = ts::fresh_db("report-cli");
  const std::string out = ::testing::TempDir() + "report-cli-out";
  expect_one_line_exit_2(station_cmd("report --db " + db + " --run 1 --out " + out), db);
  EXPECT_NE(access(db.c_str(), F_OK), 0) << "report created " << db;
  {
    station::Store store(db);
    station::RunInfo info;
    info.protocol_name = "paper";
    store.create_run(info, {{0, 1, "SN1", "up", 2.0, 9.7}});
  }
  expect_one_line_exit_2(station_cmd("report --db " + db + " --run 5 --out " + out), "no run 5");
  expect_one_line_exit_2(station_cmd("report --db " + db + " --run 1 --out " + out),
                         "no stored fit");
  expect_one_line_exit_2(
      station_cmd("report --db " + db + " --run 1 --out " + out + " --dygraphs-dir /nope"),
      "libjs-dygraphs");
  expect_one_line_exit_2(station_cmd("report --db " + db + " --run 1 --out " + out + " --pdf",
                                     "env PATH=/nonexistent"),
                         "Debian package chromium");
}

}  // namespace
