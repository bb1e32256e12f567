// History per serial: calibrations, run-to-run scatter against the SEs, and the zeta-score drift
// flag (|dk| > 3 sqrt(se_new^2 + se_prev^2)) on exact rows and on seeded synthetic fits.
#include <gtest/gtest.h>

#include <cmath>

#include "station/parts/history.hpp"
#include "station/store/calibration.hpp"
#include "tests/station/synthetic_bins.hpp"
#include "tests/station/temp_db.hpp"

namespace {

using station::SerialFitRow;
using station::testing_support::SyntheticGyro;

SerialFitRow row(std::int64_t id, std::vector<std::int64_t> runs, double k1, double se_k1,
                 double k0 = 0.01, double se_k0 = 1e-3) {
  SerialFitRow f;
  f.fit_id = id;
  f.runs = std::move(runs);
  f.terms = "dT,gradT";
  f.coefficients = {{"B0", 0.05}, {"k1", k1}, {"k0", k0}};
  f.std_errors = {{"B0", 1e-3}, {"k1", se_k1}, {"k0", se_k0}};
  return f;
}

}  // namespace

TEST(History, ZetaScoreIsTheNormalizedDifference) {
  EXPECT_DOUBLE_EQ(*station::zeta_score(5.0, 3.0, 1.0, 0.0), 4.0 / 3.0);
  EXPECT_DOUBLE_EQ(*station::zeta_score(1.0, 3.0, 5.0, 4.0), -4.0 / 5.0);
  EXPECT_FALSE(station::zeta_score(1.0, 0.0, 2.0, 0.0).has_value());
}

TEST(History, AJumpIsFlaggedOnlyBeyondThreeCombinedStandardErrors) {
  const double se = 1e-4, combined = std::sqrt(2.0) * se;
  for (const double sigmas : {2.0, 2.99, 3.01, 5.0}) {
    const std::vector<SerialFitRow> fits{row(1, {1}, 1e-3, se),
                                         row(2, {2}, 1e-3 + sigmas * combined, se)};
    const auto h = station::serial_history_stats(fits);
    ASSERT_EQ(h.calibrations.size(), 2u);
    if (sigmas < 3) {
      EXPECT_TRUE(h.flags.empty()) << sigmas;
      continue;
    }
    ASSERT_EQ(h.flags.size(), 1u) << sigmas;
    EXPECT_EQ(h.flags[0].coefficient, "k1");
    EXPECT_EQ(h.flags[0].fit_id, 2);
    EXPECT_EQ(h.flags[0].previous_fit_id, 1);
    EXPECT_NEAR(h.flags[0].zeta, sigmas, 1e-9);
  }
}

TEST(History, ARefitOfTheSameRunsIsNotANewCalibration) {
  // Fit 3 refits run 1 (e.g. other options): it replaces fit 1, and run 2's fit is compared
  // with it, not with the refit's predecessor.
  const std::vector<SerialFitRow> fits{row(1, {1}, 1e-3, 1e-4), row(2, {2}, 2e-3, 1e-4),
                                       row(3, {1}, 1.9e-3, 1e-4)};
  const auto h = station::serial_history_stats(fits);
  ASSERT_EQ(h.calibrations.size(), 2u);
  EXPECT_EQ(h.calibrations[0].fit->fit_id, 3);
  EXPECT_EQ(h.calibrations[1].fit->fit_id, 2);
  EXPECT_TRUE(h.flags.empty());  // 2e-3 vs 1.9e-3: 0.7 combined SE
}

TEST(History, ScatterAgainstTheStandardErrors) {
  // k1 = 1, 2, 3 (x 1e-3) with SE 1e-3 each: weighted mean 2e-3, chi2 = 1 + 0 + 1 = 2,
  // Birge ratio sqrt(2 / 2) = 1; sample std 1e-3; RMS SE 1e-3.
  const std::vector<SerialFitRow> fits{row(1, {1}, 1e-3, 1e-3), row(2, {2}, 2e-3, 1e-3),
                                       row(3, {3}, 3e-3, 1e-3)};
  const auto h = station::serial_history_stats(fits);
  ASSERT_EQ(h.scatter.size(), 2u);
  const auto& k1 = h.scatter[0];
  EXPECT_EQ(k1.coefficient, "k1");
  EXPECT_EQ(k1.n, 3);
  EXPECT_DOUBLE_EQ(k1.mean, 2e-3);
  EXPECT_NEAR(*k1.sample_std, 1e-3, 1e-15);
  EXPECT_NEAR(*k1.rms_se, 1e-3, 1e-15);
  EXPECT_NEAR(*k1.chi2, 2.0, 1e-9);
  EXPECT_NEAR(*k1.birge_ratio, 1.0, 1e-9);
  // k0 did not move: chi2 0, Birge ratio 0.
  EXPECT_NEAR(*h.scatter[1].birge_ratio, 0.0, 1e-12);
}

// Seeded synthetic fits through the Store: two runs of the same gyro with the same noise
// (same seed), so the fitted difference is the true jump to rounding and both fits report the
// same SE; a jump of 2 combined SEs is not flagged, one of 5 is.
TEST(History, SeededSyntheticFitsJumpingTwoSigmaAreNotFlaggedFiveSigmaAre) {
  namespace sc = station::compensation;
  station::Store store(station::testing_support::fresh_db("history_jump"));
  const sc::ModelSpec spec;  // dT, gradT: the daemon's model
  SyntheticGyro g;
  g.seed = 11;
  const auto run1 = station::testing_support::store_synthetic_run(store, {"J2", "J5"}, {g, g});
  const auto first = station::fit_serial(store, "J2", {run1}, spec);
  station::fit_serial(store, "J5", {run1}, spec);
  const double se_k1 = first.fit.std_errors[1];
  const double combined = std::sqrt(2.0) * se_k1;
  SyntheticGyro g2 = g, g5 = g;
  g2.k1 += 2.0 * combined;
  g5.k1 += 5.0 * combined;
  const auto run2 = station::testing_support::store_synthetic_run(store, {"J2", "J5"}, {g2, g5});
  station::fit_serial(store, "J2", {run2}, spec);
  station::fit_serial(store, "J5", {run2}, spec);

  const auto h2 = station::serial_history_stats(station::serial_fits(store, "J2"));
  ASSERT_EQ(h2.calibrations.size(), 2u);
  EXPECT_TRUE(h2.flags.empty());
  const auto h5 = station::serial_history_stats(station::serial_fits(store, "J5"));
  ASSERT_EQ(h5.flags.size(), 1u);
  EXPECT_EQ(h5.flags[0].coefficient, "k1");  // k0 did not move
  EXPECT_NEAR(h5.flags[0].zeta, 5.0, 1e-6);
  EXPECT_NEAR(h5.flags[0].delta, 5.0 * combined, 1e-6 * combined);
}

TEST(History, ARefitWithOtherTermsIsComparedOnlyWithItsKind) {
  // Run 2 refitted with dT only: its k1 means something else (no gradient term) and is neither
  // compared with the dT+gradT calibrations nor does it choose the scatter's terms.
  auto dt_only = row(4, {2}, 9e-3, 1e-4);
  dt_only.terms = "dT";
  const std::vector<SerialFitRow> fits{row(1, {1}, 1e-3, 1e-4), row(2, {2}, 1.1e-3, 1e-4),
                                       row(3, {3}, 1.05e-3, 1e-4), dt_only};
  const auto h = station::serial_history_stats(fits);
  EXPECT_EQ(h.calibrations.size(), 4u);
  EXPECT_EQ(h.terms, "dT,gradT");
  EXPECT_EQ(h.scatter[0].n, 3);
  EXPECT_TRUE(h.flags.empty());
}
