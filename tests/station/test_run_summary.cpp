// The end of a run where the operator looks (issue 35): `run --config` on simrig prints each
// serial's coefficients with their standard errors, the std before and after compensation and
// their ratio, the model and the verdict (or which slot names no part), and how to get the
// report, the same table `run --sim` prints (cli/run_summary, one formatter). Real processes:
// simrig on the wall clock, `station run` against it, the report written by the printed command.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "rig_process.hpp"
#include "station/store/fit_json.hpp"
#include "station/store/store.hpp"

namespace ts = station::testing_support;
using namespace std::chrono_literals;

namespace {

/// The shortest protocol that ends in a fit on the wall clock: record while the chamber heats
/// (station-made ramp at the rig's 3 C/min limit) for 150 s; with 10 s bins that is 15 bins, more
/// than the model's 3 coefficients plus the error model's 5 (compensation/correlated_errors.hpp).
constexpr const char* kProtocol =
    "name = \"summary\"\n[[step]]\ntype = \"record_start\"\n[[step]]\ntype = \"set_temperature\"\n"
    "setpoint_c = 45.0\nwait = false\n[[step]]\ntype = \"hold\"\nduration_s = 150\n"
    "[[step]]\ntype = \"record_stop\"\n";
constexpr const char* kParts = "[part.\"WIDE\"]\nB0_dph = { min = -1000.0, max = 1000.0 }\n";

std::string write(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

/// A line of `out` starting with `prefix` (empty when none).
std::string line_starting(const std::string& out, const std::string& prefix) {
  std::istringstream in(out);
  for (std::string l; std::getline(in, l);)
    if (l.rfind(prefix, 0) == 0) return l;
  return {};
}

TEST(RunSummary, RunConfigOnSimrigEndsWithEachSerialsFitVerdictAndReport) {
  const std::string dir = ::testing::TempDir() + "run-summary-" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ts::SimrigProcess rig;
  ASSERT_TRUE(rig.start("run-summary", 2)) << ts::slurp(rig.err);
  std::string config = ts::slurp(rig.config_path);
  config.insert(config.find('\n', config.find("ref_temp_c = ")) + 1, "bin_s = 10\n");
  config.insert(config.find("axis = \"up\""), "part = \"WIDE\"\n");  // slot 1 only
  write(rig.config_path, config);
  const std::string db = dir + "/rig.db";
  const pid_t p = ts::spawn_process({ts::kStationBin, "run", "--config", rig.config_path,
                                     "--protocol", write(dir + "/summary.toml", kProtocol), "--db",
                                     db, "--parts", write(dir + "/parts.toml", kParts)},
                                    dir + "/run.out", dir + "/run.err");
  const int st = ts::wait_bounded(p, 300s);
  const std::string out = ts::slurp(dir + "/run.out");
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << out << ts::slurp(dir + "/run.err");
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(^run 1 \(completed\): 0\.0\d h, \d+ ticks)")))
      << out;
  EXPECT_TRUE(std::regex_search(
      out, std::regex(R"(\nserial +B0 deg/h +k1 deg/h/C +k0 deg/h/C +std deg/h +after +ratio\n)")))
      << out;
  station::Store store(db, station::OpenMode::read_only);
  for (const auto& slot : store.run_slots(1)) {
    SCOPED_TRACE(slot.serial);
    const auto fit = store.latest_fit_of_run(slot.serial, 1);
    ASSERT_TRUE(fit.has_value()) << out;
    // The row shows this fit's numbers, as stored.
    const auto co = station::coefficients_json(fit->fit);
    const auto value = [&](const char* name) { return co.value(name, NAN); };
    EXPECT_NE(line_starting(out, slot.serial)
                  .find(fmt::format(" fit {:>11.4e} {:>11.4e} {:>10.4e}  {:>9.5f} {:>9.5f}",
                                    value("B0"), value("k1"), value("k0"), fit->eval.std_before_dph,
                                    fit->eval.std_after_dph)),
              std::string::npos)
        << out;
    const std::string model =
        fmt::format("fit {}, model {}, {} bins: ", fit->id, fit->terms, fit->fit.n_points);
    const std::string verdict =
        slot.slot == 0 ? "pass (part WIDE" : "no part limits (slot 2 names no part)";
    EXPECT_NE(out.find(model + verdict), std::string::npos) << out;
  }
  const std::string report = "station report --db " + db + " --run 1 --out report-run-1";
  ASSERT_NE(out.find("\nreport: " + report + "\n"), std::string::npos) << out;
  // The printed command writes the report.
  const auto r = ts::station_command(report.substr(8) + " >/dev/null && ls report-run-1",
                                     "run-summary-report");
  std::filesystem::remove_all("report-run-1");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("run-1.html"), std::string::npos) << r.out;
}

}  // namespace
