// Releasing a fit, verification on an independent run and `run --sim --verify` (issue 21).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <numeric>

#include "station/parts/part_file.hpp"
#include "station/release/releases.hpp"
#include "station/release/verification.hpp"
#include "station/store/calibration.hpp"
#include "station/store/fit_verdicts.hpp"
#include "tests/station/release_fixture.hpp"

namespace {

using station::testing_support::calibrated_db;
namespace sc = station::compensation;

std::int64_t fit_of_run(station::Store& store, const std::string& serial, std::int64_t run) {
  const auto f = store.latest_fit_of_run(serial, run);
  EXPECT_TRUE(f.has_value()) << serial << " run " << run;
  return f ? f->id : 0;
}

// run --sim --verify: both gyros' fits released (no part: nothing to refuse), each verified on
// the second run with a stored result and an event, and the calibration helps there too.
TEST(Release, SimVerifyReleasesThenVerifiesOnTheSecondRun) {
  const auto c = calibrated_db("release-sim");
  ASSERT_EQ(c.report["releases"].size(), 2u) << c.report.dump();
  for (const auto& r : c.report["releases"]) EXPECT_TRUE(r["released"].get<bool>()) << r.dump();
  ASSERT_EQ(c.report["verifications"].size(), 2u);
  station::Store store(c.path, station::OpenMode::read_only);
  const auto stored = station::verifications_of_run(store, c.verification_run);
  ASSERT_EQ(stored.size(), 2u);
  for (const auto& v : stored) {
    const auto rel = station::current_release(store, v.serial);
    ASSERT_TRUE(rel);
    EXPECT_EQ(v.fit_id, rel->fit_id);
    EXPECT_EQ(rel->released_by, "station run --sim --verify");
    // The simulated gyros' thermal bias dominates their noise: a calibration from another run
    // of the same gyro removes most of it (ratio well below 1; the in-sample ratio is ~0.1).
    ASSERT_TRUE(v.eval.std_ratio);
    EXPECT_LT(*v.eval.std_ratio, 0.6) << v.serial;
    EXPECT_FALSE(v.verdict) << "no part: no verification verdict";
  }
  const auto events = store.events(c.verification_run);
  EXPECT_EQ(std::count_if(events.begin(), events.end(),
                          [](const std::string& e) { return e.rfind("verification:", 0) == 0; }),
            2);
  const auto cal_events = store.events(c.calibration_run);
  EXPECT_EQ(std::count_if(cal_events.begin(), cal_events.end(),
                          [](const std::string& e) { return e.rfind("release:", 0) == 0; }),
            2);
}

TEST(Release, FailedVerdictIsReleasedOnlyWithAnOverrideThatIsStored) {
  const auto c = calibrated_db("release-fail", 1);
  station::Store store(c.path, station::OpenMode::existing);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const auto fit = fit_of_run(store, sn, c.verification_run);
  station::save_fit_verdict(
      store, fit,
      {"GX-1",
       R"({"pass":false,"failed":[{"limit":"max_std_ratio","value":0.9,"bound":0.5}],)"
       R"("part":"GX-1","checked":1})",
       std::nullopt});
  EXPECT_THROW(station::release_fit(store, {fit, "Ann", "", std::nullopt}),
               station::ReleaseRefused);
  EXPECT_NE(station::current_release(store, sn)->fit_id, fit) << "the refused one is not current";
  const auto r = station::release_fit(store, {fit, "Ann", "line 3", "customer accepts 0.9"});
  EXPECT_EQ(station::current_release(store, sn)->fit_id, fit);
  EXPECT_EQ(r.override_reason.value_or(""), "customer accepts 0.9");
  ASSERT_TRUE(r.verdict_json);
  EXPECT_NE(r.verdict_json->find("max_std_ratio"), std::string::npos);
  const auto events = store.event_rows(c.verification_run);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().kind, "release");
  EXPECT_EQ(events.back().severity, "warn");
  EXPECT_NE(events.back().message.find("customer accepts 0.9"), std::string::npos);
}

TEST(Release, NoVerdictWhileTheSlotNamesAPartNeedsAnOverride) {
  const auto c = calibrated_db("release-nopart", 1);
  station::Store store(c.path, station::OpenMode::existing);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  station::save_run_parts(store, c.verification_run, {{sn, "GX-200", "{\"number\":\"GX-200\"}"}});
  const auto fit = fit_of_run(store, sn, c.verification_run);
  try {
    station::release_fit(store, {fit, "Ann", "", std::nullopt});
    FAIL() << "released without a verdict";
  } catch (const station::ReleaseRefused& e) {
    EXPECT_NE(std::string(e.what()).find("no verdict"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("GX-200"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(station::release_fit(store, {fit, "Ann", "", "judged by hand"}));
}

TEST(Release, ANewerReleaseSupersedesTheOlderAndNothingIsDeleted) {
  const auto c = calibrated_db("release-newer", 1);
  station::Store store(c.path, station::OpenMode::existing);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const auto first = station::current_release(store, sn);
  ASSERT_TRUE(first);
  EXPECT_THROW(station::release_fit(store, {first->fit_id, "Ann", "", std::nullopt}),
               station::ReleaseRefused)
      << "the released fit released again";
  EXPECT_THROW(station::release_fit(store, {999999, "Ann", "", std::nullopt}),
               station::FitNotFound);
  const auto second = fit_of_run(store, sn, c.verification_run);
  EXPECT_THROW(station::release_fit(store, {second, "  ", "", std::nullopt}), station::InputError);
  // Text that would hide in a one-line audit trail or end an export's comment line.
  EXPECT_THROW(station::release_fit(store, {second, "Ann\nEve", "", std::nullopt}),
               station::InputError);
  EXPECT_THROW(station::release_fit(store, {second, "Ann", std::string("a\0b", 3), std::nullopt}),
               station::InputError);
  EXPECT_THROW(station::release_fit(store, {second, std::string(201, 'x'), "", std::nullopt}),
               station::InputError);
  // No verdict and no part: nothing to override; an override would record a false exception.
  EXPECT_THROW(station::release_fit(store, {second, "Ann", "", "because"}),
               station::ReleaseRefused);
  EXPECT_THROW(station::release_fit(store, {second, "Ann", "", ""}), station::InputError);
  station::release_fit(store, {second, "Bob", "", std::nullopt});
  EXPECT_EQ(station::current_release(store, sn)->fit_id, second);
  const auto all = station::releases_of(store, sn);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].fit_id, first->fit_id);
  EXPECT_TRUE(store.find_fit(first->fit_id)) << "the superseded fit stays";
  // Going back to the older calibration is a new release, not an edit.
  station::release_fit(store, {first->fit_id, "Ann", "back", std::nullopt});
  EXPECT_EQ(station::current_release(store, sn)->fit_id, first->fit_id);
  EXPECT_EQ(station::releases_of(store, sn).size(), 3u);
}

TEST(Release, AModelTheNavigationComputerCannotApplyIsRefused) {
  const auto c = calibrated_db("release-dtdt", 1);
  station::Store store(c.path, station::OpenMode::existing);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const auto f = station::fit_serial(store, sn, {c.calibration_run},
                                     {{sc::Term::dT, sc::Term::gradT, sc::Term::dTdt}, 25.0});
  try {
    station::release_fit(store, {f.fit_id, "Ann", "", "anyway"});
    FAIL() << "a dTdt model was released";
  } catch (const station::ReleaseRefused& e) {
    EXPECT_NE(std::string(e.what()).find("dTdt"), std::string::npos) << e.what();
  }
}

// Issue 34 point 10: who releases and the note reach every export and the fleet. A byte that is
// not UTF-8 ended the release in json's type_error.316 (its event's data); a bidirectional
// override was stored and went raw into the C header. Both refused by the text rule, naming the
// field and the character; a name in any script still releases.
TEST(Release, TextRuleRefusesNamesAndNotesNamingTheCharacter) {
  const auto c = calibrated_db("release-text", 1);
  station::Store store(c.path, station::OpenMode::existing);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const auto fit = fit_of_run(store, sn, c.verification_run);
  const auto refused = [&](const std::string& by, const std::string& note) {
    try {
      station::release_fit(store, {fit, by, note, std::nullopt});
    } catch (const station::InputError& e) {
      return std::string(e.what());
    }
    return std::string("released");
  };
  EXPECT_NE(refused("\xff", "")
                .find("--by NAME (who releases; JSON 'by'): byte 0xFF at byte 0 "
                      "is not UTF-8"),
            std::string::npos)
      << refused("\xff", "");
  EXPECT_NE(refused("Ann", "ok \u202Etxt.exe").find("--note (JSON 'note'): U+202E at character 4"),
            std::string::npos);
  EXPECT_NE(refused("Ann\u200F", "").find("U+200F at character 4 (byte 3)"), std::string::npos);
  EXPECT_NE(refused("Ann", "\xc2\x85").find("U+0085 at character 1 (byte 0) is a C1 control"),
            std::string::npos);
  EXPECT_NE(refused("Ann", "\xe0\x80\xaf").find("byte 0xE0 at byte 0 is not UTF-8"),
            std::string::npos)
      << "an overlong '/' is not UTF-8";
  EXPECT_NE(refused("Ann", std::string(4097, 'x')).find("4097 bytes, at most 4096"),
            std::string::npos);
  EXPECT_EQ(station::releases_of(store, sn).size(), 1u) << "nothing was stored";
  EXPECT_EQ(refused("J\u00fcrgen M\u00fcller", "5 \u00b0C, \u65e5\u672c"), "released");
}

TEST(Verify, RefusesARunTheFitUsedAndJudgesAgainstTheVerificationLimits) {
  const auto c = calibrated_db("verify-limits", 1);
  station::Store store(c.path, station::OpenMode::existing);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const auto fit = store.find_fit(station::current_release(store, sn)->fit_id);
  EXPECT_THROW(station::verify_fit(store, *fit, c.calibration_run, std::nullopt),
               station::InputError);
  station::PartLimits tight;
  tight.number = "GX-T";
  tight.max_verify_ratio = 1e-6;
  tight.max_std_ratio = 1e-6;  // a fit limit: never part of a verification's verdict
  auto v = station::verify_fit(store, *fit, c.verification_run, tight);
  ASSERT_TRUE(v.verdict);
  EXPECT_FALSE(v.verdict->pass);
  EXPECT_EQ(v.verdict->checked, 1);
  ASSERT_EQ(v.verdict->failed.size(), 1u);
  EXPECT_EQ(v.verdict->failed[0].limit, "max_verify_ratio");
  station::PartLimits loose = tight;
  loose.max_verify_ratio = 10;
  loose.max_verify_std_dph = 10;
  const auto ok = station::verify_fit(store, *fit, c.verification_run, loose);
  ASSERT_TRUE(ok.verdict);
  EXPECT_TRUE(ok.verdict->pass);
  EXPECT_EQ(ok.verdict->checked, 2);
  // The figures, recomputed independently from the bins: std, mean, and the drift as the OLS
  // slope of the compensated bias against T.
  const auto& a = v.after_dph;
  const double n = static_cast<double>(a.size());
  const double mean = std::accumulate(a.begin(), a.end(), 0.0) / n;
  EXPECT_NEAR(v.mean_residual_dph, mean, 1e-12);
  double ss = 0, sxy = 0, sxx = 0;
  const double tm = std::accumulate(v.temp_c.begin(), v.temp_c.end(), 0.0) / n;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ss += (a[i] - mean) * (a[i] - mean);
    sxy += (v.temp_c[i] - tm) * (a[i] - mean);
    sxx += (v.temp_c[i] - tm) * (v.temp_c[i] - tm);
  }
  EXPECT_NEAR(v.eval.std_after_dph, std::sqrt(ss / (n - 1)), 1e-12);
  ASSERT_TRUE(v.drift_dph_per_c);
  EXPECT_NEAR(*v.drift_dph_per_c, sxy / sxx, 1e-9 * std::abs(sxy / sxx) + 1e-15);
  // Stored and read back with its verdict.
  station::save_verification(store, v);
  const auto back = station::verifications_of_run(store, c.verification_run);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(back.back().id, v.id);
  ASSERT_TRUE(back.back().verdict);
  EXPECT_FALSE(back.back().verdict->pass);
  EXPECT_DOUBLE_EQ(back.back().eval.std_after_dph, v.eval.std_after_dph);
}

}  // namespace

namespace {

/// `station ARGS` (stdout only) and its exit status.
std::pair<int, std::string> station_cli(const std::string& args) {
  const std::string cmd =
      std::string(STATION_BINARY_DIR) + "/station/station " + args + " 2>/dev/null";
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, out};
  char buf[4096];
  std::size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int raw = pclose(p);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, out};
}

// fit --cv over the two runs: one held-out entry per run, each the RMS of the other run's fit
// applied to it, recomputed here from the store.
TEST(FitCv, LeaveOneRunOutOverTwoRunsMatchesAFitOnTheOtherRun) {
  const auto c = calibrated_db("fit-cv", 1);
  const std::string sn = c.report["gyros"][0]["serial"].get<std::string>();
  const auto [rc, out] = station_cli("fit --db " + c.path + " --serial " + sn + " --cv --json");
  ASSERT_EQ(rc, 0) << out;
  const auto j = nlohmann::json::parse(out);
  const auto& cv = j["cross_validation"];
  ASSERT_EQ(cv["held_out"].size(), 2u) << j.dump();
  {
    // Read-only: a writing Store here would hold the file's lock and refuse `station fit`.
    station::Store store(c.path, station::OpenMode::read_only);
    for (const auto& h : cv["held_out"]) {
      const auto held = h["run_id"].get<std::int64_t>();
      const auto other = held == c.calibration_run ? c.verification_run : c.calibration_run;
      const auto train = store.model_data(sn, {other}), test = store.model_data(sn, {held});
      const auto f = sc::fit_model(train.view(), {{sc::Term::dT, sc::Term::gradT}, 25.0});
      double ss = 0;
      for (const double e : sc::compensate(f, test.view())) ss += e * e;
      EXPECT_NEAR(h["rms_dph"].get<double>(), std::sqrt(ss / test.bias_dph.size()), 1e-12);
    }
  }
  EXPECT_GT(cv["pooled_rms_dph"].get<double>(), 0.0);
  // One run: no cross-validation, said in the output.
  const auto [rc1, one] = station_cli("fit --db " + c.path + " --serial " + sn + " --runs " +
                                      std::to_string(c.calibration_run) + " --cv --json");
  ASSERT_EQ(rc1, 0);
  EXPECT_TRUE(nlohmann::json::parse(one)["cross_validation"].contains("unavailable")) << one;
}

}  // namespace
