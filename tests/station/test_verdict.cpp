// Verdicts: a fit inside every limit passes; each limit fails alone with its value and bound;
// a limit the fit cannot show fails; the verdict is stored with the fit and read back.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "compensation/adev_floor.hpp"
#include "station/parts/judged_fit.hpp"
#include "station/parts/verdict.hpp"
#include "station/store/fit_verdicts.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace sc = station::compensation;
using station::LimitFailure;
using station::PartLimits;
using station::Verdict;

sc::FitResult fit_of(double b0, double k1, double k0, double se_k1, double se_k0,
                     std::size_t bins) {
  sc::FitResult f;
  f.spec.terms = {sc::Term::dT, sc::Term::gradT};
  f.names = {"B0", "k1", "k0"};
  f.coefficients = {b0, k1, k0};
  f.std_errors = {1e-3, se_k1, se_k0};
  f.n_points = bins;
  return f;
}

// A part every limit of which the reference fit below meets with a margin.
PartLimits part() {
  PartLimits p;
  p.number = "GX-1";
  p.b0_dph = {-0.2, 0.2};
  p.k1_dph_per_c = {-3e-3, 3e-3};
  p.k0_dph_per_c = {-0.06, 0.06};
  p.max_std_after_dph = 0.01;
  p.max_std_ratio = 0.5;
  p.max_adev_floor_dph = 0.02;
  p.min_complete_bins = 40;
  p.max_k1_se_dph_per_c = 1e-4;
  p.max_k0_se_dph_per_c = 2e-3;
  return p;
}

const sc::FitResult kFit = fit_of(0.05, 1.2e-3, 0.012, 4e-5, 1e-3, 66);
const sc::Evaluation kEval{0.12, 0.007, 0.0583, 94.17};

Verdict judge(const PartLimits& p, const sc::FitResult& f = kFit, const sc::Evaluation& e = kEval,
              std::optional<double> adev = 0.01) {
  return station::judge_fit(p, {f, e, adev});
}

// The one failure `v` must have.
void expect_one_failure(const Verdict& v, const std::string& limit, std::optional<double> value,
                        double bound) {
  EXPECT_FALSE(v.pass) << limit;
  ASSERT_EQ(v.failed.size(), 1u) << limit;
  EXPECT_EQ(v.failed[0].limit, limit);
  EXPECT_EQ(v.failed[0].value.has_value(), value.has_value()) << limit;
  if (value) {
    EXPECT_DOUBLE_EQ(*v.failed[0].value, *value) << limit;
  }
  EXPECT_DOUBLE_EQ(v.failed[0].bound, bound) << limit;
}

}  // namespace

TEST(Verdict, AFitInsideEveryLimitPasses) {
  const auto v = judge(part());
  EXPECT_TRUE(v.pass);
  EXPECT_TRUE(v.failed.empty());
  EXPECT_EQ(v.checked, 12);  // three ranges (6 ends) and 6 single limits
  EXPECT_EQ(station::verdict_text(v), "pass (part GX-1, 12 limits)");
}

TEST(Verdict, NoLimitsMeansNoVerdict) {
  EXPECT_EQ(station::verdict_text(std::nullopt), "no part limits");
  PartLimits empty;
  empty.number = "OPEN";
  const auto v = judge(empty);
  EXPECT_TRUE(v.pass);
  EXPECT_EQ(v.checked, 0);
}

TEST(Verdict, EachLimitFailsAloneWithItsValueAndBound) {
  auto p = part();
  // Each limit moved just past the reference fit's value: only that one fails.
  p.b0_dph.max = 0.04;
  expect_one_failure(judge(p), "B0_dph.max", 0.05, 0.04);
  p = part();
  p.b0_dph.min = 0.06;
  p.b0_dph.max = 0.1;
  expect_one_failure(judge(p), "B0_dph.min", 0.05, 0.06);
  p = part();
  p.k1_dph_per_c.max = 1e-3;
  expect_one_failure(judge(p), "k1_dph_per_c.max", 1.2e-3, 1e-3);
  p = part();
  p.k1_dph_per_c.min = 1.3e-3;
  expect_one_failure(judge(p), "k1_dph_per_c.min", 1.2e-3, 1.3e-3);
  p = part();
  p.k0_dph_per_c.max = 0.01;
  expect_one_failure(judge(p), "k0_dph_per_c.max", 0.012, 0.01);
  p = part();
  p.k0_dph_per_c.min = 0.02;
  expect_one_failure(judge(p), "k0_dph_per_c.min", 0.012, 0.02);
  p = part();
  p.max_std_after_dph = 0.005;
  expect_one_failure(judge(p), "max_std_after_dph", 0.007, 0.005);
  p = part();
  p.max_std_ratio = 0.05;
  expect_one_failure(judge(p), "max_std_ratio", 0.0583, 0.05);
  p = part();
  p.max_adev_floor_dph = 0.009;
  expect_one_failure(judge(p), "max_adev_floor_dph", 0.01, 0.009);
  p = part();
  p.min_complete_bins = 67;
  expect_one_failure(judge(p), "min_complete_bins", 66, 67);
  p = part();
  p.max_k1_se_dph_per_c = 3e-5;
  expect_one_failure(judge(p), "max_k1_se_dph_per_c", 4e-5, 3e-5);
  p = part();
  p.max_k0_se_dph_per_c = 5e-4;
  expect_one_failure(judge(p), "max_k0_se_dph_per_c", 1e-3, 5e-4);
}

TEST(Verdict, AValueOnTheBoundPasses) {
  auto p = part();
  p.k1_dph_per_c = {1.2e-3, 1.2e-3};
  p.min_complete_bins = 66;
  p.max_std_after_dph = 0.007;
  EXPECT_TRUE(judge(p).pass);
}

TEST(Verdict, ALimitTheFitCannotShowFails) {
  // No gradT term: k0 and its SE are not shown; no 1 Hz record: no ADEV floor; undefined ratio.
  sc::FitResult no_k0 = kFit;
  no_k0.spec.terms = {sc::Term::dT};
  no_k0.names = {"B0", "k1"};
  no_k0.coefficients.pop_back();
  no_k0.std_errors.pop_back();
  const sc::Evaluation undefined{1e-12, 1e-12, std::nullopt, std::nullopt};
  const auto v = judge(part(), no_k0, undefined, std::nullopt);
  EXPECT_FALSE(v.pass);
  std::vector<std::string> limits;
  for (const auto& f : v.failed) {
    limits.push_back(f.limit);
    EXPECT_FALSE(f.value.has_value()) << f.limit;
  }
  EXPECT_EQ(limits,
            (std::vector<std::string>{"k0_dph_per_c.min", "k0_dph_per_c.max", "max_std_ratio",
                                      "max_adev_floor_dph", "max_k0_se_dph_per_c"}));
}

TEST(Verdict, JsonAndTextCarryEveryFailure) {
  auto p = part();
  p.k1_dph_per_c.max = 1e-3;
  p.min_complete_bins = 70;
  const auto v = judge(p);
  const auto j = station::verdict_json(v);
  EXPECT_EQ(j["pass"], false);
  ASSERT_EQ(j["failed"].size(), 2u);
  EXPECT_EQ(j["failed"][0]["limit"], "k1_dph_per_c.max");
  EXPECT_DOUBLE_EQ(j["failed"][0]["value"].get<double>(), 1.2e-3);
  EXPECT_DOUBLE_EQ(j["failed"][0]["bound"].get<double>(), 1e-3);
  EXPECT_EQ(station::verdict_json(station::verdict_from_json(j)), j);
  EXPECT_EQ(station::verdict_text(v),
            "FAIL (part GX-1): k1_dph_per_c.max 0.0012 > 0.001 (by 0.0002); min_complete_bins 66 "
            "< 70 (by 4)");
}

TEST(Verdict, IsStoredWithItsFitAndReadBack) {
  station::Store store(station::testing_support::fresh_db("verdict_store"));
  const auto id = store.save_fit("SN1", {1}, kFit, kEval);
  EXPECT_FALSE(station::stored_verdict(store, id).has_value());  // judged against nothing yet
  auto p = part();
  p.max_std_ratio = 0.05;
  station::SerialFit sf{"SN1", {1}, kFit, kEval, id};
  const auto judged = station::judge_and_store(store, sf, p);
  const auto back = station::stored_verdict(store, id);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(station::verdict_json(*back), station::verdict_json(*judged.verdict));
  EXPECT_FALSE(back->pass);
  const auto cols = station::load_fit_verdict(store, id);
  EXPECT_EQ(cols.part_number, "GX-1");
  // No 1 Hz samples stored for run 1: the floor is unmeasured, and that limit fails too.
  EXPECT_FALSE(cols.adev_floor_dph.has_value());
  EXPECT_EQ(back->failed.back().limit, "max_adev_floor_dph");
}

TEST(Verdict, AdevFloorOfWhiteNoiseIsItsLongestWellDeterminedTau) {
  // White rate noise of std s: ADEV(tau) = s / sqrt(tau) (IEEE 952 C.1, tau0 = 1 s), falling
  // to the longest octave tau whose edf >= 10. With N = 60000 that is tau = 4096 s (white-FM
  // edf 20.0; tau = 8192 s has 9.0), where s_hat / sigma has a relative std of about
  // sqrt(1 / (2 edf)) = 16 %: the floor lies within 3 x 16 % of s / 64.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 0.5);
  std::vector<double> rate(60000);
  for (auto& r : rate) r = n(rng);
  const auto floor = sc::adev_floor(rate, 1.0);
  ASSERT_TRUE(floor.has_value());
  EXPECT_DOUBLE_EQ(floor->tau_s, 4096.0);
  EXPECT_GE(floor->edf, sc::kAdevFloorMinEdf);
  EXPECT_NEAR(floor->adev, 0.5 / 64.0, 0.48 * 0.5 / 64.0);
  EXPECT_FALSE(sc::adev_floor(std::vector<double>(3, 1.0), 1.0).has_value());
}
