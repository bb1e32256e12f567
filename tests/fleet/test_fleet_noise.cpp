// `station fleet --propose-noise` (issue 32, point 3): simulated stations forward runs of gyros
// whose noise the simulator knows (sim_devices/counter_board_gyro.hpp: ARW 0.003 deg/sqrt(h),
// Gauss-Markov 0.003 deg/h over 1 h, RRW 1e-4 deg/h/sqrt(h)); the proposal from the fleet's
// PostgreSQL recovers the ARW within the error of a median of the runs, counts the runs it could
// not use, and its block reads back through the part-file parser. The pooling's rules (fewer than
// 3 runs, the trust factor from the spread) are checked on values whose spread is known.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "sim_devices/counter_board_gyro.hpp"
#include "station/fleet/fleet_noise.hpp"
#include "station/parts/part_file.hpp"
#include "station/store/sqlite.hpp"
#include "tests/fleet/fleet_fixture.hpp"

namespace station::testing_support {
namespace {

namespace sc = station::compensation;
using fleet::NoiseProposal;
using fleet::RunNoise;

constexpr const char* kPart = "RLG-N";
constexpr double kSimArw = 0.003;  // sim_devices NoiseParams::arw_dpsh, deg/sqrt(h)
// Earth rate along a vertical input axis at 39.9 N (the simulated station's latitude):
// 15.041 sin(39.9 deg). It moves the angle by 6 pulses a second, so the counter's quantisation
// error changes from one sample to the next, as on the simulated rig.
constexpr double kEarthRateDph = 9.6474;

/// `hours` of one simulated RLG at a constant 25 C (its thermal bias constant, so B0 alone
/// compensates it), at the station's 1 Hz: rate from the net pulses, as the counter board gives
/// it (pulse quantisation included).
std::vector<SampleRow> static_record(std::uint64_t seed, double hours) {
  sim::GyroConfig g;
  g.seed = seed;
  g.earth_rate_dph = kEarthRateDph;
  sim::RlgGyroModel gyro(g);
  gyro.step_to(3.0 * 3600.0, 25.0);  // the Gauss-Markov part starts at 0: 3 correlation times
  std::vector<SampleRow> rows;
  std::int64_t last = gyro.net_pulses();
  const double t0 = gyro.time_s();
  for (int i = 1; i <= static_cast<int>(hours * 3600.0); ++i) {
    gyro.step_to(t0 + i, 25.0);
    SampleRow s;
    s.serial = "SIM";
    s.t_s = i;
    s.rate_dph = static_cast<double>(gyro.net_pulses() - last) * g.pulse_weight_arcsec;  // /1 s
    s.temp_c = s.temp2_c = 25.0;
    s.recording = true;
    last = gyro.net_pulses();
    rows.push_back(s);
  }
  return rows;
}

/// The estimates of `records` static records of 16 h (estimate_run_noise, a B0-only model).
std::vector<RunNoise> static_runs(int records) {
  sc::FitResult b0_only;
  b0_only.spec = sc::ModelSpec{{}, 25.0};
  b0_only.names = {"B0"};
  b0_only.coefficients = {0.0};
  std::vector<RunNoise> runs;
  for (int i = 0; i < records; ++i) {
    RunNoise r;
    r.part = kPart;
    r.station = "bench";
    r.serial = fmt::format("SIM-{}", i);
    r.run_uuid = fmt::format("static-{}", i);
    runs.push_back(
        fleet::estimate_run_noise(r, static_record(100 + i, 16.0), kEarthRateDph, b0_only, 600.0));
  }
  return runs;
}

/// 4 standard errors of the difference of two medians in ln, each sqrt(pi / 2) s / sqrt(n)
/// (Kendall & Stuart §10.10), s the spread between runs (1.4826 MAD of ln).
double four_se_of_ln_difference(const fleet::PooledTerm& a, const fleet::PooledTerm& b) {
  const double half_pi = std::numbers::pi / 2.0;
  return 4.0 * std::sqrt(half_pi * *a.log_sd * *a.log_sd / a.runs_with +
                         half_pi * *b.log_sd * *b.log_sd / b.runs_with);
}

class FleetNoise : public FleetTest {
 protected:
  /// A station `name` whose `gyros` simulated gyros of part RLG-N ran the short cycle once,
  /// forwarded with or without its 1 Hz samples.
  static void station_forwards(const std::string& name, int gyros, std::uint64_t seed,
                               bool samples) {
    const std::string parts = ::testing::TempDir() + "fleet_noise_parts.toml";
    std::ofstream(parts) << "[part.\"" << kPart << "\"]\ndescription = \"fleet noise test\"\n";
    const auto db = fresh_db("fleet_noise_" + name);
    auto o = short_cycle_run(db, gyros);
    o.seed = seed;
    o.parts_path = parts;
    station::run_simulated(o);
    Database(db, OpenMode::existing).exec(fmt::format("UPDATE runs SET station = '{}'", name));
    fleet::ForwardOptions f;
    f.samples = samples;
    f.station = name;
    fleet::Forwarder fw(db, target(), f);
    for (int i = 0; i < 10'000 && fw.pass().more; ++i) {
    }
  }
};

TEST_F(FleetNoise, ProposalFromThreeStationsRecoversTheArw) {
  station_forwards("rig-a", 4, 21, true);
  station_forwards("rig-b", 4, 22, true);
  station_forwards("rig-c", 4, 23, true);
  station_forwards("rig-d", 2, 24, false);  // its samples never reach the fleet
  fleet::PgConnection pg(target());
  const auto runs = fleet::fleet_run_noise(pg, {});
  const auto proposals = fleet::propose_noise(runs);
  ASSERT_EQ(proposals.size(), 1u);
  const NoiseProposal& p = proposals[0];
  EXPECT_EQ(p.runs, 14);
  EXPECT_EQ(p.usable, 12);
  EXPECT_EQ(p.stations, 3);
  ASSERT_EQ(p.unusable.size(), 2u);  // counted and named, not dropped
  for (const auto& r : p.unusable) {
    EXPECT_EQ(r.station, "rig-d");
    EXPECT_NE(r.problem.find("no 1 Hz samples"), std::string::npos) << r.problem;
  }
  ASSERT_TRUE(p.prior.has_value()) << p.why_none;
  const auto& n = p.terms[0];
  ASSERT_TRUE(n.median && n.median_se && n.log_sd);
  // The median of 12 estimates with a run's SE: its SE is sqrt(pi / 2) SE / sqrt(12)
  // (Kendall & Stuart §10.10); 4 of them. The run's SE is wide (0.0012): at 1 s the counter's
  // 1.5 arcsec quantisation (Q) is 17x the ARW in Allan variance, and N is read beside it.
  const double se_median = std::sqrt(std::numbers::pi / 2.0) * *n.median_se / std::sqrt(12.0);
  EXPECT_NEAR(*n.median, kSimArw, 4.0 * se_median);
  // Measured: N 0.00256 (the fit gives Q 0.457 arcsec where uniform quantisation has 0.433, and
  // N the rest), B 0.008 (the Gauss-Markov bump read as flicker), no K. The same estimator on
  // 16 h static records of the same gyro gives the same N and B within the spread between runs:
  // compensating a thermal ramp and the trip through the fleet add nothing to them.
  const auto bench = fleet::propose_noise(static_runs(7));
  ASSERT_EQ(bench.size(), 1u);
  ASSERT_TRUE(bench[0].prior.has_value()) << bench[0].why_none;
  for (int t : {0, 1}) {
    const auto &fleet_term = p.terms[t], &bench_term = bench[0].terms[t];
    ASSERT_TRUE(fleet_term.median && bench_term.median) << fleet_term.key;
    EXPECT_NEAR(std::log(*fleet_term.median / *bench_term.median), 0.0,
                four_se_of_ln_difference(fleet_term, bench_term))
        << fleet_term.key << "\n"
        << noise_toml(p) << noise_toml(bench[0]);
  }
  EXPECT_GE(p.prior->trust_factor, std::exp(*n.log_sd));
  EXPECT_GE(p.prior->trust_factor, sc::kMinNoiseTrust);
  if (!p.prior->rrw_dph_rt_h) EXPECT_FALSE(p.terms[2].why_not.empty());  // said, not silent
  // The block, pasted into a part file, reads back as the same prior (to its 4 digits).
  const auto file = parse_part_file(noise_toml(p), "proposed.toml");
  ASSERT_TRUE(file.parts.contains(kPart));
  const auto& back = file.parts.at(kPart).noise;
  ASSERT_TRUE(back.has_value());
  EXPECT_NEAR(*back->arw_deg_rt_h, *p.prior->arw_deg_rt_h, 5e-4 * kSimArw);
  EXPECT_EQ(back->bias_instability_dph.has_value(), p.prior->bias_instability_dph.has_value());
  EXPECT_EQ(back->rrw_dph_rt_h.has_value(), p.prior->rrw_dph_rt_h.has_value());
  EXPECT_DOUBLE_EQ(back->trust_factor, p.prior->trust_factor);
}

/// A usable run of `part` whose terms are N, B, K (0: the run's fit dropped it).
RunNoise run_of(const std::string& part, int i, double n, double b, double k) {
  RunNoise r;
  r.part = part;
  r.station = i % 2 == 0 ? "rig-a" : "rig-b";
  r.serial = fmt::format("SN-{}", i);
  r.run_uuid = fmt::format("run-{}", i);
  sc::NoiseTerms t;
  t.angle_random_walk_deg_rth = n;
  if (b > 0) t.bias_instability_dph = b;
  if (k > 0) t.rate_random_walk_dph_rth = k;
  r.terms = t;
  return r;
}

TEST(FleetNoisePooling, FewerThanThreeUsableRunsGiveNoProposalAndSayWhy) {
  std::vector<RunNoise> runs = {run_of("P2", 0, 0.003, 0.002, 1e-4),
                                run_of("P2", 1, 0.003, 0.002, 1e-4)};
  RunNoise garbage = run_of("P2", 2, 0, 0, 0);
  garbage.terms.reset();
  garbage.problem = "no 1 Hz samples in the fleet database";
  runs.push_back(garbage);
  const auto p = fleet::propose_noise(runs);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_FALSE(p[0].prior.has_value());
  EXPECT_EQ(p[0].runs, 3);
  EXPECT_EQ(p[0].usable, 2);
  EXPECT_NE(p[0].why_none.find("2 usable run(s) of 3"), std::string::npos) << p[0].why_none;
  const auto toml = fleet::noise_toml(p[0]);
  EXPECT_EQ(toml.find("[part."), std::string::npos) << toml;  // nothing to paste by mistake
  EXPECT_NE(toml.find("not used: run run-2"), std::string::npos) << toml;
  EXPECT_TRUE(fleet::noise_proposal_json(p[0])["trust_factor"].is_null());
}

// ln N, ln B, ln K normal with known sigmas across 401 runs: the trust factor is
// exp(s sqrt(1 + pi / 2n)) for the widest, s estimated by 1.4826 MAD, whose standard error for
// normal data is 1.166 s / sqrt(n) (the MAD's asymptotic variance, Huber & Ronchetti §5.1), so 4
// of those bound it; a K absent from most runs is not proposed.
TEST(FleetNoisePooling, TrustFactorIsTheWidestSpreadBetweenRuns) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> z(0.0, 1.0);
  constexpr int kRuns = 401;
  constexpr double kSdN = 0.05, kSdB = 0.4;
  std::vector<RunNoise> runs;
  for (int i = 0; i < kRuns; ++i)
    runs.push_back(run_of("P", i, 0.003 * std::exp(kSdN * z(rng)), 0.002 * std::exp(kSdB * z(rng)),
                          i % 3 == 0 ? 1e-4 : 0.0));
  const auto p = fleet::propose_noise(runs);
  ASSERT_EQ(p.size(), 1u);
  ASSERT_TRUE(p[0].prior.has_value());
  const double tol = 4.0 * 1.166 / std::sqrt(double{kRuns});
  EXPECT_NEAR(*p[0].terms[0].log_sd, kSdN, tol * kSdN);
  EXPECT_NEAR(*p[0].terms[1].log_sd, kSdB, tol * kSdB);
  const double widen = std::sqrt(1.0 + std::numbers::pi / (2.0 * kRuns));
  EXPECT_NEAR(std::log(p[0].prior->trust_factor), kSdB * widen, tol * kSdB + 0.01);
  // The medians: within 4 SE of the median, sqrt(pi / 2) s / sqrt(n) in ln.
  const double se_ln = std::sqrt(std::numbers::pi / 2.0 / kRuns);
  EXPECT_NEAR(std::log(*p[0].prior->arw_deg_rt_h / 0.003), 0.0, 4.0 * se_ln * kSdN);
  EXPECT_NEAR(std::log(*p[0].prior->bias_instability_dph / 0.002), 0.0, 4.0 * se_ln * kSdB);
  EXPECT_FALSE(p[0].prior->rrw_dph_rt_h.has_value());  // seen in a third of the runs only
  EXPECT_NE(p[0].terms[2].why_not.find("absent from"), std::string::npos) << p[0].terms[2].why_not;
  // And the part file reads the block back.
  const auto file = parse_part_file(fleet::noise_toml(p[0]), "proposed.toml");
  EXPECT_FALSE(file.parts.at("P").noise->rrw_dph_rt_h.has_value());
}

}  // namespace
}  // namespace station::testing_support
