// Test helper for the export round trip (test_export_roundtrip.cpp: the formats;
// test_gyro_tc_function.cpp: the shipped C function): a released fit of one simulated gyro, its
// block, and its runs' bins and 1 Hz record with the station's compensated values.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "station/release/block_formats.hpp"
#include "station/store/calibration.hpp"
#include "tests/station/release_fixture.hpp"
#include "tests/station/rig_process.hpp"

namespace station::testing_support {

/// Bins or 1 Hz record of one gyro in one run, with the station's compensated values.
struct ExportRecord {
  compensation::ModelData data;
  std::vector<double> station_dph;
};

inline std::vector<ExportRecord> export_records(Store& store, const FitRecord& fit) {
  std::vector<ExportRecord> out;
  for (const auto run : fit.runs)
    for (auto d :
         {store.model_data(fit.serial, {run}), fitted_record_model_data(store, run, fit.serial)})
      out.push_back({d, compensation::compensate(fit.fit, d.view())});
  return out;
}

/// Applies `b` to every record; the largest difference from the station, relative to the
/// largest bias magnitude (the scale of the numbers involved).
inline double worst_relative(const gyro_tc_block& b, const std::vector<ExportRecord>& recs) {
  double worst = 0;
  for (const auto& r : recs) {
    double scale = 0;
    for (const double x : r.data.bias_dph) scale = std::max(scale, std::abs(x));
    for (std::size_t i = 0; i < r.station_dph.size(); ++i) {
      const double c = gyro_tc_correct(&b, r.data.bias_dph[i], r.data.temp_c[i], r.data.grad_c[i]);
      worst = std::max(worst, std::abs(c - r.station_dph[i]) / scale);
    }
  }
  return worst;
}

/// A block as a consumer reads it from the JSON export (`serial`, `part` keep its strings).
inline gyro_tc_block block_from_json(const nlohmann::json& j, std::string& serial,
                                     std::string& part) {
  serial = j["serial"].get<std::string>();
  part = j["part_number"].is_null() ? "" : j["part_number"].get<std::string>();
  gyro_tc_block b{};
  b.serial = serial.c_str();
  b.part_number = part.c_str();
  b.fit_id = j["fit_id"].get<long long>();
  b.released = j["released"].get<bool>() ? 1 : 0;
  b.t_ref_c = j["t_ref_c"].get<double>();
  const auto& s = j["span"];
  b.t_min_c = s["t_min_c"].get<double>();
  b.t_max_c = s["t_max_c"].get<double>();
  b.grad_min_c = s["grad_min_c"].get<double>();
  b.grad_max_c = s["grad_max_c"].get<double>();
  const auto& c = j["coefficients"];
  b.b0_dph = c.value("B0", 0.0);
  for (int i = 0; i < 4; ++i) b.k_dph[i] = c.value("k" + std::to_string(i + 1), 0.0);
  b.k0_dph_per_c = c.value("k0", 0.0);
  b.crc32 =
      static_cast<uint32_t>(std::stoul(j["checksum"]["crc32"].get<std::string>(), nullptr, 16));
  const auto& sf = j["scale_factor"];
  if (sf["measured"].get<bool>()) {
    b.sf_measured = 1;
    b.sf_k0_pulse_per_arcsec = sf["k0_pulse_per_arcsec"].get<double>();
    b.sf_tc_ppm_per_c = sf["tc_ppm_per_c"].get<double>();
    b.sf_t_ref_c = sf["t_ref_c"].get<double>();
    b.sf_t_min_c = sf["span"]["t_min_c"].get<double>();
    b.sf_t_max_c = sf["span"]["t_max_c"].get<double>();
    b.pulse_weight_arcsec = sf["pulse_weight_arcsec"].get<double>();
    b.earth_rate_dph = sf["earth_rate_dph"].get<double>();
  }
  return b;
}

/// The C compiler the build uses, or empty when there is none to run.
inline std::string c_compiler() {
  const std::string cc = STATION_C_COMPILER;
  if (cc.empty() || std::system((cc + " --version >/dev/null 2>&1").c_str()) != 0) return "";
  return cc;
}

/// A fresh directory under the test's temporary directory.
inline std::string scratch_dir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + name + "_" + std::to_string(getpid());
  EXPECT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  return dir;
}

/// Compiles `dir`/`main` as C99 with -pedantic -Werror and `flags` next to gyro_tc.h; empty on
/// success, else the compiler's messages.
inline std::string compile_c(const std::string& cc, const std::string& dir, const std::string& main,
                             const std::string& flags = "-Wall -Wextra") {
  const std::string build = cc + " -std=c99 -pedantic " + flags + " -Werror -I" +
                            STATION_SOURCE_DIR + "/station/release " + dir + "/" + main + " -o " +
                            dir + "/prog 2>" + dir + "/cc.log";
  return std::system(build.c_str()) == 0 ? "" : "compile failed: " + slurp(dir + "/cc.log");
}

/// `b` with a scale-factor model set by hand (37 ppm above a 1.5 arcsec nominal pulse weight,
/// +3.25 ppm/C, ladders over -10..60 C), sealed again.
inline CoefficientBlock with_scale_factor(CoefficientBlock b) {
  ScaleFactorModel m;
  m.k0_pulse_per_arcsec = (1.0 + 37e-6) / 1.5;
  m.k0_se_pulse_per_arcsec = 2e-6;
  m.tc_ppm_per_c = 3.25;
  m.tc_se_ppm_per_c = 0.4;
  m.t_ref_c = 25.0;
  m.t_min_c = -10.0;
  m.t_max_c = 60.0;
  m.plateaus = 3;
  m.runs = {1};
  m.pulse_weight_arcsec = 1.5;
  m.earth_rate_dph = 12.3;
  b.scale_factor = {m, "set by hand"};
  seal_block(b);
  return b;
}

/// A released fit of one simulated gyro (short cycle) with its block and records.
class ExportRoundTrip : public ::testing::Test {
 protected:
  void SetUp() override {
    cal_ = calibrated_db("export-roundtrip", 1);
    store_.emplace(cal_.path, OpenMode::existing);
    serial_ = cal_.report["gyros"][0]["serial"].get<std::string>();
    rel_ = current_release(*store_, serial_);
    ASSERT_TRUE(rel_);
    fit_ = *store_->find_fit(rel_->fit_id);
    block_ = make_block(*store_, fit_, rel_);
    recs_ = export_records(*store_, fit_);
  }
  CalibratedDb cal_;
  std::optional<Store> store_;
  std::string serial_;
  std::optional<ReleaseRow> rel_;
  FitRecord fit_;
  CoefficientBlock block_;
  std::vector<ExportRecord> recs_;
};

}  // namespace station::testing_support
