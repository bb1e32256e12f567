// The shipped C function (gyro_tc.h) on the compiled header: the bias model alone reproduces the
// station on the run's own 1 Hz record (issue 21); with a scale factor (issue 36) the corrected
// rate is the output over K(T) minus the bias in input units, checked against the formula by
// hand; a block without one keeps its canonical text and checksum bit for bit; a block built
// from a simulated acceptance run carries the scale factor its ladders gave.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "station/acceptance/acceptance_run.hpp"
#include "station/sim/sim_run.hpp"
#include "tests/station/export_fixture.hpp"

namespace {

using station::testing_support::c_compiler;
using station::testing_support::compile_c;
using station::testing_support::ExportRoundTrip;
using station::testing_support::scratch_dir;
using station::testing_support::slurp;
using station::testing_support::with_scale_factor;

// The C header, compiled by the C compiler with -std=c99 -pedantic -Werror next to gyro_tc.h,
// applied by a C program to the 1 Hz record written as text: gyro_tc_correct (the bias) equals
// the station's compensation, and gyro_tc_rate_dph of a block without a scale factor is exactly
// the rate minus the bias model.
TEST_F(ExportRoundTrip, CHeaderCompiledAsCReproducesTheStation) {
  const std::string cc = c_compiler();
  if (cc.empty()) GTEST_SKIP() << "no C compiler (" << STATION_C_COMPILER << ")";
  ASSERT_FALSE(block_.scale_factor.model) << "the short cycle has no rate ladder";
  const std::string dir = scratch_dir("gyro_tc_c");
  std::ofstream(dir + "/calibrations.h") << station::blocks_c_header({block_});
  std::ofstream(dir + "/apply.c") << R"(#include <locale.h>
#include <stdio.h>
#include "calibrations.h"
int main(void) {
  double bias, t, g, c;
  const gyro_tc_block *b = gyro_tc_calibrations_blocks[0];
  if (GYRO_TC_CALIBRATIONS_BLOCK_COUNT != 1 || !gyro_tc_verify(b) || !b->released) return 3;
  /* A consumer in a decimal-comma locale still verifies (where the machine has one). */
  if (setlocale(LC_NUMERIC, "de_DE.UTF-8") != NULL && !gyro_tc_verify(b)) return 4;
  setlocale(LC_NUMERIC, "C");
  while (scanf("%lf %lf %lf", &bias, &t, &g) == 3) {
    c = gyro_tc_correct(b, bias, t, g);
    if (gyro_tc_rate_dph(b, bias, t, g) != c) return 5; /* the scale left alone */
    printf("%.17g\n", c);
  }
  return 0;
}
)";
  ASSERT_EQ(compile_c(cc, dir, "apply.c"), "");
  const auto& rec = recs_.back();  // the 1 Hz record
  {
    std::ofstream in(dir + "/in.txt");
    for (std::size_t i = 0; i < rec.station_dph.size(); ++i)
      in << fmt::format("{:.17g} {:.17g} {:.17g}\n", rec.data.bias_dph[i], rec.data.temp_c[i],
                        rec.data.grad_c[i]);
  }
  ASSERT_EQ(std::system((dir + "/prog <" + dir + "/in.txt >" + dir + "/out.txt").c_str()), 0)
      << "the C program refused the block (exit 3: checksum; 5: the scale was touched)";
  std::ifstream out(dir + "/out.txt");
  double scale = 0, worst = 0, v = 0;
  for (const double x : rec.data.bias_dph) scale = std::max(scale, std::abs(x));
  std::size_t n = 0;
  while (out >> v) {
    worst = std::max(worst, std::abs(v - rec.station_dph[n]) / scale);
    ++n;
  }
  EXPECT_EQ(n, rec.station_dph.size());
  EXPECT_LE(worst, 1e-9);
}

gyro_tc_block hand_block() {
  gyro_tc_block b{};
  b.serial = "X";
  b.part_number = "";
  b.t_ref_c = 25;
  b.t_min_c = -40;
  b.t_max_c = 70;
  b.grad_min_c = -0.5;
  b.grad_max_c = 1.5;
  b.b0_dph = 0.1;
  b.k_dph[0] = 2e-3;
  b.k_dph[1] = -1e-5;
  b.k0_dph_per_c = 0.03;
  return b;
}

TEST(GyroTc, ClampsTemperatureAndGradientToTheSpanTheFitSaw) {
  gyro_tc_block b = hand_block();
  // Inside: the polynomial written out by hand.
  const double dt = 10 - 25.0;
  EXPECT_NEAR(gyro_tc_bias_dph(&b, 10, 0.4), 0.1 + 2e-3 * dt - 1e-5 * dt * dt + 0.03 * 0.4, 1e-15);
  // Outside: the value at the edge of the span, never an extrapolation.
  EXPECT_DOUBLE_EQ(gyro_tc_bias_dph(&b, 95, 3), gyro_tc_bias_dph(&b, 70, 1.5));
  EXPECT_DOUBLE_EQ(gyro_tc_bias_dph(&b, -60, -2), gyro_tc_bias_dph(&b, -40, -0.5));
  EXPECT_DOUBLE_EQ(gyro_tc_correct(&b, 1.0, 10, 0.4), 1.0 - gyro_tc_bias_dph(&b, 10, 0.4));
  // A block whose span is reversed never verifies, whatever its checksum.
  b.t_min_c = 80;
  EXPECT_EQ(gyro_tc_verify(&b), 0);
}

// Issue 36, the formula by hand (IEEE 647 / 952 scale-factor model): a gyro 40 ppm above its
// nominal 1.5 arcsec pulse weight at 25 C with +3 ppm/C, ladders over 0..50 C, the bias fitted
// where the Earth rate along the axis was 10.5 deg/h. At 100 deg/s and 40 C, then at 80 C
// (beyond both spans: the bias at 70 C, the scale factor at 50 C).
TEST(GyroTc, TheRateIsTheOutputOverKMinusTheBiasInInputUnits) {
  gyro_tc_block b = hand_block();
  const double rate_dph = 100.0 * 3600.0;  // nominal: output pulses/s * 1.5
  EXPECT_EQ(gyro_tc_rate_dph(&b, rate_dph, 40, 0.4), rate_dph - gyro_tc_bias_dph(&b, 40, 0.4))
      << "not measured: the scale left alone";
  b.sf_measured = 1;
  b.sf_k0_pulse_per_arcsec = (1 + 40e-6) / 1.5;
  b.sf_tc_ppm_per_c = 3.0;
  b.sf_t_ref_c = 25;
  b.sf_t_min_c = 0;
  b.sf_t_max_c = 50;
  b.pulse_weight_arcsec = 1.5;
  b.earth_rate_dph = 10.5;
  EXPECT_EQ(gyro_tc_verify(&b), 0) << "the checksum is not set yet";
  {
    const double bias = 0.1 + 2e-3 * 15 - 1e-5 * 225 + 0.03 * 0.4;  // B(40 C, 0.4 C)
    const double k = (1 + 40e-6) / 1.5 * (1 + 3.0e-6 * 15);         // K(40 C), pulse/arcsec
    const double pps = rate_dph / 1.5;
    const double expected = pps / k - ((bias + 10.5) / (k * 1.5) - 10.5);
    EXPECT_NEAR(gyro_tc_scale_factor_pulse_per_arcsec(&b, 40), k, 1e-15 * k);
    EXPECT_NEAR(gyro_tc_rate_dph(&b, rate_dph, 40, 0.4), expected, 1e-12 * std::abs(expected));
    // Beside the bias, the scale factor takes 85 ppm of 360000 deg/h: about 30.6 deg/h.
    EXPECT_NEAR(rate_dph - bias - gyro_tc_rate_dph(&b, rate_dph, 40, 0.4), 30.6, 0.01);
  }
  {
    const double bias = 0.1 + 2e-3 * 45 - 1e-5 * 2025 + 0.03 * 1.5;  // B(70 C, 1.5 C)
    const double k = (1 + 40e-6) / 1.5 * (1 + 3.0e-6 * 25);          // K(50 C)
    const double expected = -rate_dph / 1.5 / k - ((bias + 10.5) / (k * 1.5) - 10.5);
    EXPECT_NEAR(gyro_tc_rate_dph(&b, -rate_dph, 80, 3), expected, 1e-12 * std::abs(expected));
  }
  // At rest where the bias was fitted, the bias model alone was exact: the scale factor must not
  // correct it a second time (the Earth rate's scale error is in B already).
  const double at_rest_dph = 10.5 + gyro_tc_bias_dph(&b, 40, 0.4);
  EXPECT_NEAR(gyro_tc_rate_dph(&b, at_rest_dph, 40, 0.4), 10.5, 1e-12 * 10.5);
  // A scale factor that reaches zero over its span cannot be divided by: never verifies.
  b.sf_tc_ppm_per_c = -4e4;
  EXPECT_EQ(gyro_tc_scale_factor_ok(&b), 0);
  // Nor one that is no gyro's (K w beyond 1 +- GYRO_TC_MAX_SF_DEVIATION anywhere on its span: a
  // ladder the gyro did not follow), nor a w or an Earth rate that is not a number.
  b.sf_tc_ppm_per_c = 3.0;
  EXPECT_EQ(gyro_tc_scale_factor_ok(&b), 1);
  b.sf_tc_ppm_per_c = 500.0;  // K w = 1.0125 at 50 C
  EXPECT_EQ(gyro_tc_scale_factor_ok(&b), 0);
  b.sf_tc_ppm_per_c = 3.0;
  b.sf_k0_pulse_per_arcsec = 1.96e-8;
  EXPECT_EQ(gyro_tc_scale_factor_ok(&b), 0);
  b.sf_k0_pulse_per_arcsec = (1 + 40e-6) / 1.5;
  b.earth_rate_dph = std::nan("");
  EXPECT_EQ(gyro_tc_scale_factor_ok(&b), 0);
  b.earth_rate_dph = 10.5;
  b.pulse_weight_arcsec = std::numeric_limits<double>::infinity();
  EXPECT_EQ(gyro_tc_scale_factor_ok(&b), 0);
}

// Issue 36: gyro_tc/4 is a new name for blocks with a scale factor only. A block without one
// (every block delivered before) writes the text and checksum the previous header wrote, bit for
// bit (the literals below are that header's output, station 0.x before issue 36), and a C header
// written for it (initializers ending at crc32) still compiles and verifies.
TEST(GyroTc, AnOldBlocksCanonicalTextAndChecksumAreUnchanged) {
  const std::string old_text =
      "gyro_tc/2;serial=RLG-2311-0043;part=GX-200;fit=7;released=1;t_ref_c=25;t_min_c=-38.25;"
      "t_max_c=68.5;grad_min_c=-0.5;grad_max_c=1.5;b0_dph=0.10000000000000001;k1=0.002;"
      "k2=-1.0000000000000001e-05;k3=2.9999999999999997e-08;k4=0;k0=0.029999999999999999";
  const std::string old_escaped =
      "gyro_tc/3;serial=A%3BB%25;part=;fit=8;released=0;t_ref_c=25;t_min_c=-38.25;t_max_c=68.5;"
      "grad_min_c=-0.5;grad_max_c=1.5;b0_dph=0.10000000000000001;k1=0.002;"
      "k2=-1.0000000000000001e-05;k3=2.9999999999999997e-08;k4=0;k0=0.029999999999999999";
  gyro_tc_block b = hand_block();
  b.serial = "RLG-2311-0043";
  b.part_number = "GX-200";
  b.fit_id = 7;
  b.released = 1;
  b.t_min_c = -38.25;
  b.t_max_c = 68.5;
  b.k_dph[2] = 3e-8;
  char text[GYRO_TC_CANONICAL_MAX];
  int n = gyro_tc_canonical(&b, text, sizeof text);
  ASSERT_GT(n, 0);
  EXPECT_EQ(std::string(text, static_cast<std::size_t>(n)), old_text);
  EXPECT_EQ(gyro_tc_crc32(text, static_cast<std::size_t>(n)), 0xf3166474u);
  b.serial = "A;B%";
  b.part_number = "";
  b.fit_id = 8;
  b.released = 0;
  n = gyro_tc_canonical(&b, text, sizeof text);
  ASSERT_GT(n, 0);
  EXPECT_EQ(std::string(text, static_cast<std::size_t>(n)), old_escaped);
  EXPECT_EQ(gyro_tc_crc32(text, static_cast<std::size_t>(n)), 0x66c03344u);

  const std::string cc = c_compiler();
  if (cc.empty()) GTEST_SKIP() << "no C compiler: the old header is not compiled";
  const std::string dir = scratch_dir("gyro_tc_old");
  std::ofstream(dir + "/old.c") << R"(#include <stdio.h>
#include <string.h>
#include "gyro_tc.h"
static const gyro_tc_block old = {
    "RLG-2311-0043", "GX-200", 7LL, 1, /* serial, part, fit, released */
    25, -38.25, 68.5, -0.5, 1.5, 0.10000000000000001,
    {0.002, -1.0000000000000001e-05, 2.9999999999999997e-08, 0}, 0.029999999999999999,
    0xf3166474u};
int main(void) {
  char text[GYRO_TC_CANONICAL_MAX];
  if (!gyro_tc_verify(&old) || old.sf_measured != 0) return 3;
  if (gyro_tc_rate_dph(&old, 20.0, 30.0, 0.0) != gyro_tc_correct(&old, 20.0, 30.0, 0.0)) return 4;
  if (gyro_tc_canonical(&old, text, sizeof text) < 0) return 5;
  fputs(text, stdout);
  return 0;
}
)";
  // -Wall, not -Wextra: its missing-field-initializers notes the new fields (gyro_tc.h says so).
  ASSERT_EQ(compile_c(cc, dir, "old.c", "-Wall"), "");
  ASSERT_EQ(std::system((dir + "/prog >" + dir + "/out.txt").c_str()), 0);
  EXPECT_EQ(slurp(dir + "/out.txt"), old_text);
}

// Issue 36: a block with a scale factor in the generated C header, compiled and applied by a C
// program over the record's temperatures and beyond the ladders' span, at rest and at table
// rates: gyro_tc_rate_dph equals the formula written out here within 1e-12 relative.
TEST_F(ExportRoundTrip, CHeaderWithAScaleFactorCompiledAsCAppliesBoth) {
  const std::string cc = c_compiler();
  if (cc.empty()) GTEST_SKIP() << "no C compiler (" << STATION_C_COMPILER << ")";
  auto other = block_;
  other.fit_id += 1000;  // another name in the header
  const auto sf = with_scale_factor(other);
  const std::string dir = scratch_dir("gyro_tc_sf");
  const std::string header = station::blocks_c_header({sf, block_});
  EXPECT_NE(header.find("scale factor: K0 0.666691333"), std::string::npos) << header;
  EXPECT_NE(header.find("/* scale factor: not measured (sf_measured 0) */"), std::string::npos);
  std::ofstream(dir + "/calibrations.h") << header;
  std::ofstream(dir + "/apply.c") << R"(#include <stdio.h>
#include "calibrations.h"
int main(void) {
  double r, t, g;
  const gyro_tc_block *b = gyro_tc_calibrations_blocks[0];
  if (!gyro_tc_verify(b) || b->sf_measured != 1 || !gyro_tc_verify(gyro_tc_calibrations_blocks[1]))
    return 3;
  while (scanf("%lf %lf %lf", &r, &t, &g) == 3) printf("%.17g\n", gyro_tc_rate_dph(b, r, t, g));
  return 0;
}
)";
  ASSERT_EQ(compile_c(cc, dir, "apply.c"), "");
  std::vector<std::array<double, 3>> in;  // nominal rate deg/h, T, gradT
  const auto& rec = recs_.back();
  for (std::size_t i = 0; i < rec.data.temp_c.size(); i += 97)
    for (const double table_dph : {0.0, 3600.0 * 1.0, -3600.0 * 300.0})
      in.push_back(
          {rec.data.bias_dph[i] + 12.3 + table_dph, rec.data.temp_c[i], rec.data.grad_c[i]});
  in.push_back({3600.0 * 50, -30.0, 0.2});  // below the ladders' -10 C
  in.push_back({3600.0 * 50, 65.0, 0.2});   // above their 60 C
  {
    std::ofstream f(dir + "/in.txt");
    for (const auto& x : in) f << fmt::format("{:.17g} {:.17g} {:.17g}\n", x[0], x[1], x[2]);
  }
  ASSERT_EQ(std::system((dir + "/prog <" + dir + "/in.txt >" + dir + "/out.txt").c_str()), 0)
      << "the C program refused the block";
  const gyro_tc_block c = sf.c_block();
  std::ifstream out(dir + "/out.txt");
  std::size_t n = 0;
  for (double v = 0; out >> v; ++n) {
    ASSERT_LT(n, in.size());
    const auto& x = in[n];
    const double t_sf = std::clamp(x[1], -10.0, 60.0);
    const double k = (1.0 + 37e-6) / 1.5 * (1.0 + 3.25e-6 * (t_sf - 25.0));
    const double bias = gyro_tc_bias_dph(&c, x[1], x[2]);  // the bias model, tested above
    const double expected = x[0] / 1.5 / k - ((bias + 12.3) / (k * 1.5) - 12.3);
    EXPECT_NEAR(v, expected, 1e-12 * std::max(std::abs(expected), 1.0)) << n;
  }
  EXPECT_EQ(n, in.size());
}

// Issue 36 end to end: the shipped acceptance protocol on the simulated rig (1 gyro), its record
// fitted; the block of that fit carries the scale factor across the run's plateaus as
// run_acceptance computes it, recovers the simulated K0 and TC within 4 SE, and `station release`
// and `station export` show it.
TEST(ScaleFactorBlock, AnAcceptanceRunsLaddersGiveTheBlocksScaleFactor) {
  station::SimRunOptions o;
  o.db_path = station::testing_support::fresh_db("sf-block");
  o.protocol = "acceptance";
  o.progress = false;
  o.fresh = true;
  o.gyros = 1;
  o.seed = 3;
  const auto r = station::run_simulated(o);
  ASSERT_TRUE(r.contains("acceptance")) << r.dump();
  const std::int64_t run = r["run_id"].get<std::int64_t>();
  const std::string serial = r["gyros"][0]["serial"].get<std::string>();
  auto store_holder = std::make_optional<station::Store>(o.db_path, station::OpenMode::existing);
  station::Store& store = *store_holder;
  namespace sc = station::compensation;
  const auto fitted = station::fit_serial(store, serial, {run}, {{sc::Term::dT}, 25.0});
  const auto fit = *store.find_fit(fitted.fit_id);
  const auto block = station::make_block(store, fit, std::nullopt);
  ASSERT_TRUE(block.scale_factor.model) << block.scale_factor.note;
  const auto& m = *block.scale_factor.model;
  const auto acc = station::run_acceptance(store, run, 25.0);
  ASSERT_EQ(acc.size(), 1u);
  ASSERT_TRUE(acc[0].sf_vs_temp && acc[0].sf_vs_temp->ok());
  const auto& t = acc[0].sf_vs_temp->value();
  EXPECT_EQ(m.k0_pulse_per_arcsec, t.sf_ref_pulse_per_arcsec);
  EXPECT_EQ(m.tc_ppm_per_c, t.tc_ppm_per_c);
  EXPECT_EQ(m.tc_se_ppm_per_c.value_or(-1), t.tc_se_ppm_per_c);
  EXPECT_EQ(m.plateaus, 3u);
  EXPECT_EQ(m.runs, std::vector<std::int64_t>{run});
  double lo = 1e9, hi = -1e9;
  for (const auto& l : acc[0].ladders) lo = std::min(lo, l.temp_c), hi = std::max(hi, l.temp_c);
  EXPECT_EQ(m.t_min_c, lo);
  EXPECT_EQ(m.t_max_c, hi);
  EXPECT_GT(hi - lo, 20.0) << "cold, room and hot plateaus";
  const auto slot = store.run_slots(run).at(0);
  EXPECT_EQ(m.pulse_weight_arcsec, slot.pulse_weight_arcsec);
  EXPECT_EQ(m.earth_rate_dph, slot.earth_rate_dph);
  const auto& truth = r["acceptance"][0]["true"];
  // K0 against the same definition on the noise-free gyro (the ladders' least-squares lines at
  // T_ref; a nonlinear gyro's line is not its small-rate scale factor, 10 ppm apart here).
  const auto& line_truth = r["acceptance"][0]["sf_vs_temp"]["true"];
  EXPECT_LE(std::abs(m.k0_pulse_per_arcsec - line_truth["sf_ref_pulse_per_arcsec"].get<double>()),
            4 * m.k0_se_pulse_per_arcsec);
  EXPECT_LE(std::abs(m.tc_ppm_per_c - truth["sf_tc_ppm_per_c"].get<double>()),
            4 * *m.tc_se_ppm_per_c);
  const gyro_tc_block c = block.c_block();
  EXPECT_EQ(gyro_tc_verify(&c), 1);
  EXPECT_EQ(block.canonical.rfind("gyro_tc/4;", 0), 0u);
  store_holder.reset();  // one writer at a time: the commands below open it

  const auto e = station::testing_support::station_command(
      fmt::format("export --db {} --fit {} --format json", o.db_path, fit.id), "sf-export");
  ASSERT_EQ(e.status, 0) << e.out;
  EXPECT_NE(e.out.find("\"measured\": true"), std::string::npos) << e.out;
  const auto rel = station::testing_support::station_command(
      fmt::format("release --db {} --fit {} --by Ann", o.db_path, fit.id), "sf-release");
  ASSERT_EQ(rel.status, 0) << rel.out;
  EXPECT_NE(rel.out.find(fmt::format("scale factor: K0 {:.9g}", m.k0_pulse_per_arcsec)),
            std::string::npos)
      << rel.out;
}

// Issue 36: a run with one rate ladder holds the serial to that ladder's K at its temperature:
// the block gets it with TC 0 and says so.
TEST(ScaleFactorBlock, OneLadderGivesItsKWithNoTemperatureCoefficientNoted) {
  const std::string path = station::testing_support::fresh_db("one_ladder") + ".toml";
  std::ofstream(path) << "name = \"one_ladder\"\n[[step]]\ntype = \"lock_turntable\"\n"
                         "[[step]]\ntype = \"rate_ladder\"\nrates_dps = [10, 50, 100]\n"
                         "dwell_s = 60\n[[step]]\ntype = \"lock_turntable\"\n";
  station::SimRunOptions o;
  o.db_path = station::testing_support::fresh_db("one_ladder");
  o.protocol = path;
  o.progress = false;
  o.fresh = true;
  o.gyros = 1;
  const auto r = station::run_simulated(o);
  ASSERT_EQ(r["state"], "completed") << r.dump();
  const std::int64_t run = r["run_id"].get<std::int64_t>();
  station::Store store(o.db_path, station::OpenMode::read_only);
  station::FitRecord fit;  // what find_scale_factor reads of a fit: serial, runs, T_ref
  fit.serial = r["gyros"][0]["serial"].get<std::string>();
  fit.runs = {run};
  fit.fit.spec.ref_temp_c = 25.0;
  const auto acc = station::run_acceptance(store, run, 25.0);
  ASSERT_EQ(acc.size(), 1u);
  ASSERT_EQ(acc[0].ladders.size(), 1u);
  const auto& ladder = acc[0].ladders[0];
  ASSERT_TRUE(ladder.fit.ok()) << ladder.fit.error();
  const auto sf = station::find_scale_factor(store, fit);
  ASSERT_TRUE(sf.model) << sf.note;
  EXPECT_EQ(sf.model->k0_pulse_per_arcsec, ladder.fit->sf_pulse_per_arcsec);
  EXPECT_EQ(sf.model->k0_se_pulse_per_arcsec, ladder.fit->sf_se_pulse_per_arcsec);
  EXPECT_EQ(sf.model->tc_ppm_per_c, 0.0);
  EXPECT_FALSE(sf.model->tc_se_ppm_per_c);
  EXPECT_EQ(sf.model->t_ref_c, ladder.temp_c);
  EXPECT_EQ(sf.model->t_min_c, ladder.temp_c);
  EXPECT_EQ(sf.model->t_max_c, ladder.temp_c);
  EXPECT_NE(sf.note.find("no temperature coefficient measured, taken as 0"), std::string::npos)
      << sf.note;
  EXPECT_NE(station::scale_factor_text(sf).find("TC not measured (0)"), std::string::npos)
      << station::scale_factor_text(sf);
}

}  // namespace
