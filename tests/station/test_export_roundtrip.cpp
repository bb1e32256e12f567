// The round trip of issue 21, the formats: a released fit exported as JSON, CSV and a PX4
// parameter file, read back as a consumer would and applied with gyro_tc.h to the run's own bins
// and 1 Hz record, compared with the station's compensated values; the scale factor in each
// format, or the format saying it has none (issue 36); text in a block escaped for each reader.
// The checksum is checked against zlib's independent CRC-32. The C function on the compiled
// header: test_gyro_tc_function.cpp.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/station/export_fixture.hpp"

namespace {

namespace sc = station::compensation;
using nlohmann::json;
using station::testing_support::block_from_json;
using station::testing_support::export_records;
using station::testing_support::ExportRoundTrip;
using station::testing_support::slurp;
using station::testing_support::worst_relative;

/// The CSV's rows by column name (its cells here hold no comma).
std::vector<std::map<std::string, std::string>> csv_rows(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  std::stringstream hs(line);
  for (std::string h; std::getline(hs, h, ',');) head.push_back(h);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::map<std::string, std::string> row;
    std::size_t i = 0;
    for (std::string f; std::getline(ls, f, ',') && i < head.size(); ++i) row[head[i]] = f;
    rows.push_back(row);
  }
  return rows;
}

TEST_F(ExportRoundTrip, JsonBlockVerifiesAndReproducesTheStation) {
  const json j = json::parse(station::block_json(block_).dump(2));
  EXPECT_EQ(j["release"]["by"], rel_->released_by);
  EXPECT_EQ(j["outside_span"], "clamp");
  EXPECT_EQ(j["terms"], json({"B0", "k1", "k0"}));
  EXPECT_EQ(j["units"]["k1"], "deg/h/C");
  // The checksum, recomputed with zlib (an independent CRC-32) over the canonical text.
  const std::string canon = j["checksum"]["canonical"].get<std::string>();
  const auto z =
      crc32(0L, reinterpret_cast<const Bytef*>(canon.data()), static_cast<uInt>(canon.size()));
  EXPECT_EQ(j["checksum"]["crc32"].get<std::string>(), fmt::format("0x{:08x}", z));
  std::string sn, pn;
  gyro_tc_block b = block_from_json(j, sn, pn);
  EXPECT_EQ(gyro_tc_verify(&b), 1);
  EXPECT_LE(worst_relative(b, recs_), 1e-9);
  // Every bin mean and every binned sample lies inside the span: no clamping on the fit's data.
  for (const auto& r : recs_)
    for (std::size_t i = 0; i < r.data.temp_c.size(); ++i) {
      ASSERT_GE(r.data.temp_c[i], b.t_min_c);
      ASSERT_LE(r.data.temp_c[i], b.t_max_c);
    }
  // One ulp changed in a coefficient: the block no longer verifies.
  b.k_dph[0] = std::nextafter(b.k_dph[0], 1.0);
  EXPECT_EQ(gyro_tc_verify(&b), 0);
}

// Migration 8: the span is stored with the fit, from the bins' own ranges. It must be exactly the
// range of the 1 Hz samples of the fit's complete bins (what every version before computed at
// export), and a fit stored before (span NULL) must export the identical block.
TEST_F(ExportRoundTrip, StoredSpanIsTheSamplesSpanAndOlderFitsExportTheSame) {
  ASSERT_TRUE(fit_.span);
  double t_lo = 1e300, t_hi = -1e300, g_lo = 1e300, g_hi = -1e300;
  std::size_t n = 0;
  for (const auto run : fit_.runs) {
    const auto d = station::fitted_record_model_data(*store_, run, fit_.serial);
    for (std::size_t i = 0; i < d.temp_c.size(); ++i, ++n) {
      t_lo = std::min(t_lo, d.temp_c[i]);
      t_hi = std::max(t_hi, d.temp_c[i]);
      g_lo = std::min(g_lo, d.grad_c[i]);
      g_hi = std::max(g_hi, d.grad_c[i]);
    }
  }
  ASSERT_GT(n, 1000u);
  EXPECT_EQ(*fit_.span, (station::FitSpan{t_lo, t_hi, g_lo, g_hi}));
  EXPECT_LT(t_lo, t_hi);
  EXPECT_LT(g_lo, g_hi);
  store_->db().exec(
      "UPDATE fits SET temp_min_c = NULL, temp_max_c = NULL, grad_min_c = NULL, "
      "grad_max_c = NULL WHERE id = " +
      std::to_string(fit_.id));
  const auto old = *store_->find_fit(fit_.id);
  EXPECT_FALSE(old.span);
  const auto again = station::make_block(*store_, old, rel_);
  EXPECT_EQ(again.canonical, block_.canonical);
  EXPECT_EQ(again.crc32, block_.crc32);
}

// Issue 34 defect 6: before the text rule a serial like "A;part=B" was accepted and released;
// its block went out with gyro_tc/2's checksum, which the release did not store, and gyro_tc.h
// now checksums such text as gyro_tc/3. Exporting the release again would ship a checksum the
// firmware holding the old header refuses: the export is refused, naming the serial and why.
// A fit of it that is not released still gets a block (verification, `export --fit`).
TEST_F(ExportRoundTrip, AReleasedLegacySerialWithASemicolonIsRefusedNotReChecksummed) {
  const std::string legacy = "A;part=B";
  std::string sql = "PRAGMA foreign_keys = OFF;";
  for (const char* table :
       {"gyros", "run_slots", "samples", "bins", "fits", "releases", "verifications"})
    sql += fmt::format("UPDATE {} SET serial = '{}' WHERE serial = '{}';", table, legacy, serial_);
  sql += fmt::format("UPDATE runs SET resolved_json = replace(resolved_json, '\"{}\"', '\"{}\"');",
                     serial_, legacy);
  store_->db().exec(sql);
  const auto rel = station::current_release(*store_, legacy);
  ASSERT_TRUE(rel);
  const auto fit = *store_->find_fit(rel->fit_id);
  ASSERT_EQ(fit.serial, legacy);
  try {
    station::make_block(*store_, fit, rel);
    ADD_FAILURE() << "a released legacy serial was exported with a new checksum";
  } catch (const station::ReleaseRefused& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("serial 'A;part=B'"), std::string::npos) << what;
    EXPECT_NE(what.find("gyro_tc/2"), std::string::npos) << what;
    EXPECT_NE(what.find("nothing exported"), std::string::npos) << what;
  }
  const auto unreleased = station::make_block(*store_, fit, std::nullopt);
  EXPECT_EQ(unreleased.canonical.rfind("gyro_tc/3;serial=A%3Bpart=B;", 0), 0u)
      << unreleased.canonical;
}

TEST_F(ExportRoundTrip, CsvRowsReproduceTheStation) {
  const auto rows = csv_rows(station::blocks_csv({block_}));
  ASSERT_EQ(rows.size(), 3u);
  std::string sn = rows[0].at("serial"), pn = rows[0].at("part_number");
  gyro_tc_block b{};
  b.serial = sn.c_str();
  b.part_number = pn.c_str();
  b.fit_id = std::stoll(rows[0].at("fit_id"));
  b.released = rows[0].at("released") == "yes" ? 1 : 0;
  EXPECT_EQ(b.released, 1);
  b.t_ref_c = std::stod(rows[0].at("t_ref_c"));
  b.t_min_c = std::stod(rows[0].at("t_min_c"));
  b.t_max_c = std::stod(rows[0].at("t_max_c"));
  b.grad_min_c = std::stod(rows[0].at("grad_min_c"));
  b.grad_max_c = std::stod(rows[0].at("grad_max_c"));
  for (const auto& r : rows) {
    const double v = std::stod(r.at("value"));
    const std::string t = r.at("term");
    if (t == "B0") b.b0_dph = v;
    if (t == "k1") b.k_dph[0] = v;
    if (t == "k0") b.k0_dph_per_c = v;
  }
  b.crc32 = static_cast<uint32_t>(std::stoul(rows[0].at("crc32"), nullptr, 16));
  EXPECT_EQ(gyro_tc_verify(&b), 1);
  EXPECT_LE(worst_relative(b, recs_), 1e-9);
}

// PX4's TC_G layout holds a cubic in dT: a released dT,dT2,dT3 fit round-trips through the
// parameter file (rad/s there), a gradient model is refused.
TEST_F(ExportRoundTrip, Px4ParameterFileReproducesACubicFitAndRefusesAGradient) {
  EXPECT_THROW(station::block_px4(block_, {0, 2}), station::InputError);
  const auto cubic = station::fit_serial(*store_, serial_, fit_.runs,
                                         {{sc::Term::dT, sc::Term::dT2, sc::Term::dT3}, 25.0});
  station::release_fit(*store_, {cubic.fit_id, "Ann", "cubic for PX4", std::nullopt});
  const auto rec = *store_->find_fit(cubic.fit_id);
  const auto block = station::make_block(*store_, rec, station::current_release(*store_, serial_));
  const std::string text = station::block_px4(block, {1, 2});
  std::map<std::string, double> p;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string vehicle, comp, name, type;
    double value = 0;
    ls >> vehicle >> comp >> name >> value >> type;
    EXPECT_EQ(type, name == "TC_G1_ID" ? "6" : "9") << line;
    p[name] = value;
  }
  ASSERT_EQ(p.size(), 8u) << text;
  const double to_dph = 180.0 * 3600.0 / M_PI;
  std::string sn = serial_, pn;
  gyro_tc_block b{};
  b.serial = sn.c_str();
  b.part_number = pn.c_str();
  b.t_ref_c = p.at("TC_G1_TREF");
  b.t_min_c = p.at("TC_G1_TMIN");
  b.t_max_c = p.at("TC_G1_TMAX");
  b.grad_min_c = -1e9;
  b.grad_max_c = 1e9;
  b.b0_dph = p.at("TC_G1_X0_2") * to_dph;
  for (int i = 1; i <= 3; ++i) b.k_dph[i - 1] = p.at(fmt::format("TC_G1_X{}_2", i)) * to_dph;
  EXPECT_LE(worst_relative(b, export_records(*store_, rec)), 1e-9);
}

// Text in a block's comments cannot end the comment: no code or parameter line gets in.
TEST_F(ExportRoundTrip, CommentTextCannotInjectCodeOrParameters) {
  auto b = block_;
  b.release->note = "*/ int evil = 1; /* x";
  b.release->released_by = "Eve\n1\t1\tTC_G0_TMAX\t999\t9";
  b.serial = "X\"1,\n*/ bad";
  const std::string c = station::blocks_c_header({b});
  EXPECT_EQ(c.find("*/ int evil"), std::string::npos) << c;
  EXPECT_EQ(c.find("\n*/ bad"), std::string::npos) << c;
  EXPECT_NE(c.find("\"X\\\"1,\\012*/ bad\""), std::string::npos)
      << "the literal keeps the serial: " << c;
  auto cubic = b;
  cubic.names = {"B0", "k1"};
  cubic.coefficients = {0.1, 1e-3};
  cubic.std_errors = {0.01, 1e-4};
  const std::string px4 = station::block_px4(cubic, {0, 2});
  EXPECT_EQ(px4.find("\n1\t1\tTC_G0_TMAX\t999"), std::string::npos) << px4;
}

// Issue 36: a block with a scale factor carries it in JSON and CSV (read back, the block
// verifies: the checksum covers it) and the PX4 file, which has no parameter for it, says so
// with the value; the short cycle has no rate ladder, so its own block says "not measured".
TEST_F(ExportRoundTrip, TheScaleFactorTravelsInJsonAndCsvAndPx4SaysItCannotHoldIt) {
  const json none = station::block_json(block_);
  EXPECT_EQ(none["scale_factor"]["measured"], false);
  EXPECT_NE(none["scale_factor"]["note"].get<std::string>().find("not measured"),
            std::string::npos);
  EXPECT_EQ(none["checksum"]["canonical"].get<std::string>().rfind("gyro_tc/2;", 0), 0u);
  const auto sf = station::testing_support::with_scale_factor(block_);
  EXPECT_EQ(sf.canonical.rfind("gyro_tc/4;", 0), 0u) << sf.canonical;
  EXPECT_EQ(sf.canonical.substr(0, block_.canonical.size()).substr(9),
            block_.canonical.substr(9));  // the bias part unchanged, the scale factor after it
  const json j = json::parse(station::block_json(sf).dump(2));
  EXPECT_EQ(j["scale_factor"]["tc_se_ppm_per_c"], 0.4);
  EXPECT_EQ(j["scale_factor"]["runs"], json({1}));
  std::string sn, pn;
  gyro_tc_block b = block_from_json(j, sn, pn);
  EXPECT_EQ(gyro_tc_verify(&b), 1);
  b.sf_tc_ppm_per_c = std::nextafter(b.sf_tc_ppm_per_c, 0.0);
  EXPECT_EQ(gyro_tc_verify(&b), 0) << "the checksum covers the scale factor";
  const auto rows = csv_rows(station::blocks_csv({sf, block_}));
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(rows[0].at("scale_factor"), "measured");
  EXPECT_EQ(std::stod(rows[0].at("sf_k0_pulse_per_arcsec")), (1.0 + 37e-6) / 1.5);
  EXPECT_EQ(std::stod(rows[0].at("sf_tc_ppm_per_c")), 3.25);
  EXPECT_EQ(std::stod(rows[0].at("earth_rate_dph")), 12.3);
  EXPECT_EQ(rows[3].at("scale_factor"), "not measured");
  EXPECT_EQ(rows[3].at("sf_k0_pulse_per_arcsec"), "");
  auto cubic = sf;
  cubic.names = {"B0", "k1"};
  cubic.coefficients = {0.1, 1e-3};
  cubic.std_errors = {0.01, 1e-4};
  const std::string px4 = station::block_px4(cubic, {0, 2});
  EXPECT_NE(px4.find("\n# SCALE FACTOR NOT IN THIS FILE: PX4's TC_G parameters hold no scale "
                     "factor"),
            std::string::npos)
      << px4;
  EXPECT_NE(px4.find("K0 0.666691333"), std::string::npos) << px4;
  cubic.scale_factor = block_.scale_factor;
  EXPECT_NE(station::block_px4(cubic, {0, 2}).find("\n# scale factor: not measured"),
            std::string::npos);
}

}  // namespace

// Issue 34 point 10: whatever text a block carries (an older record, or one the text rule never
// saw), each format escapes for its reader. A U+202E in a serial or a release note went raw into
// the C header's comments (g++ -Werror=bidi-chars refused it) and a note starting "=HYPERLINK("
// became a spreadsheet formula in the CSV.
class HostileText : public ExportRoundTrip {
 protected:
  void SetUp() override {
    ExportRoundTrip::SetUp();
    hostile_ = block_;
    hostile_.serial = "GX\u202E1;part=*/ ??/";
    hostile_.part_number = "P\u2066N%3B";
    hostile_.terms = "dT*/\u202Eq";
    hostile_.release->note = "=HYPERLINK(\"http://x.example/\",\"ok\u202E\")\nnext */ line";
    hostile_.release->released_by = "@SUM(1+1)\xff";
    hostile_.release->override_reason = "-2+3";
    station::seal_block(hostile_);
  }
  station::CoefficientBlock hostile_;
};

TEST_F(HostileText, CHeaderCompilesUnderBidiCharsErrorAndVerifies) {
  const std::string cc = STATION_C_COMPILER;
  if (cc.empty() || std::system((cc + " --version >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << "no C compiler (" << cc << ")";
  const std::string dir = ::testing::TempDir() + "gyro_tc_bidi_" + std::to_string(getpid());
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  // -Wbidi-chars is GCC 12's (CVE-2021-42574): a compiler without it cannot judge this header.
  if (std::system((cc + " -Werror=bidi-chars -x c -fsyntax-only /dev/null 2>/dev/null").c_str()) !=
      0)
    GTEST_SKIP() << cc << " has no -Wbidi-chars";
  const std::string header = station::blocks_c_header({hostile_, block_});
  for (const unsigned char c : header)
    ASSERT_TRUE(c == '\n' || (c >= 0x20 && c < 0x7f)) << "byte 0x" << std::hex << int{c};
  std::ofstream(dir + "/calibrations.h") << header;
  std::ofstream(dir + "/check.c") << R"(#include <string.h>
#include "calibrations.h"
int main(void) {
  const gyro_tc_block *b = gyro_tc_calibrations_blocks[0];
  return GYRO_TC_CALIBRATIONS_BLOCK_COUNT == 2 && gyro_tc_verify(b) &&
         gyro_tc_verify(gyro_tc_calibrations_blocks[1]) &&
         strcmp(b->serial, "GX\342\200\2561;part=*/ ?\?/") == 0 ? 0 : 3;
}
)";
  const std::string build = cc + " -std=c99 -pedantic -Wall -Wextra -Werror -Werror=bidi-chars -I" +
                            STATION_SOURCE_DIR + "/station/release " + dir + "/check.c -o " + dir +
                            "/check 2>" + dir + "/cc.log";
  ASSERT_EQ(std::system(build.c_str()), 0) << slurp(dir + "/cc.log") << header;
  EXPECT_EQ(std::system((dir + "/check").c_str()), 0) << "the C program refused the block";
  const std::string cxx = "g++ -Werror=bidi-chars -fsyntax-only -x c++ -I" +
                          std::string(STATION_SOURCE_DIR) + "/station/release " + dir +
                          "/calibrations.h 2>" + dir + "/cxx.log";
  EXPECT_EQ(std::system(cxx.c_str()), 0) << slurp(dir + "/cxx.log");
}

TEST_F(HostileText, CsvCellsAreNeverFormulasAndStayOneRecordPerLine) {
  const std::string csv = station::blocks_csv({hostile_});
  EXPECT_NE(csv.find(",\"'=HYPERLINK(\"\"http://x.example/\"\",\"\"ok\u202E\"\")\nnext */ line\","),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",\"'@SUM(1+1)\uFFFD\","), std::string::npos) << csv;  // and valid UTF-8
  EXPECT_NE(csv.find(",\"'-2+3\","), std::string::npos) << csv;
  // No cell's content starts with a formula character, quoted or not (a spreadsheet evaluates
  // a quoted "=1+1" too): the cells read back by RFC 4180.
  std::vector<std::string> cells{""};
  bool quoted = false;
  for (std::size_t i = 0; i < csv.size(); ++i) {
    const char c = csv[i];
    if (quoted && c == '"' && i + 1 < csv.size() && csv[i + 1] == '"') {
      cells.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (!quoted && (c == ',' || c == '\n')) {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  EXPECT_FALSE(quoted);
  EXPECT_GT(cells.size(), 3 * 24u);
  for (const auto& cell : cells)
    if (!cell.empty() && (cell[0] < '0' || cell[0] > '9'))  // numbers may be negative
      EXPECT_EQ(std::string("=+@\t\r").find(cell[0]), std::string::npos) << cell;
  EXPECT_NE(std::find(cells.begin(), cells.end(), "'-2+3"), cells.end());
}

TEST_F(HostileText, JsonExportOfAnOlderRecordIsValidUtf8) {
  // A release stored before the text rule, with a byte that is not UTF-8: the export ended in
  // json's type_error.316.
  store_->db().exec("UPDATE releases SET note = CAST(X'41FF42' AS TEXT) WHERE id = " +
                    std::to_string(rel_->id));
  const auto o = station::testing_support::station_command(
      "export --db " + cal_.path + " --serial " + serial_ + " --format json", "json-utf8");
  EXPECT_EQ(o.status, 0) << o.out;
  EXPECT_NE(o.out.find("\"note\": \"A\uFFFDB\""), std::string::npos) << o.out;
}
