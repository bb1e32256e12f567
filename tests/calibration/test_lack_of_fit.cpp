// Monte-Carlo power and size of the lack-of-fit check (issue 32, compensation/model_choice.hpp):
// a term the fitted paper model (B0 + k1 dT + k0 gradT) lacks must be named, under every noise
// row of NoiseCoverage, in at least 80 % of the realizations, and a correctly specified model
// warned about in at most 10 %. The simulator is the test's own (noise_sim.hpp): the paper
// cycle's bins, the noise added by methods unlike the station's error model.
//
// The missing terms, each the size the issue measured (k2 = 1e-5 deg/h/C^2; dT/dt 0.004
// deg/h per C/h) or, for the two it gives no size for (k3 dT^3 and kg gradT dT), the size at which
// the term shows in the bins as much as that k2 term does: the part of it the fitted model cannot
// absorb (its residual after least squares on B0, dT and gradT) has the same norm.
//
// Where no test can reach 80 % the bound is what one could: the oracle that knows the noise's
// true covariance (generalized least squares, computed here from the sample covariance of many
// realizations of the noise alone). Its power, the candidate's z beyond the same Bonferroni
// bound (with a known covariance the most powerful unbiased test of one coefficient), bounds how
// often the fit can find the term: strong flicker hides a k2 = 1e-5 term from any test (the
// oracle finds it in 39 % of flicker B 0.006 realizations). It does not bound naming, which must
// also tell the term from the other candidates: a noise wander shaped like one candidate makes
// another fit better even under the true covariance. So the oracle also names, on the same
// realizations, the candidate of largest |z| beyond the bound (each z in the model extended by it
// alone); under Gauss-Markov noise it finds dT3 in 0.92 and names it in 0.71. Each cell asserts
// two shares: the fit finds the term (its own ratio beyond the bound) in at least min(0.80, the
// oracle's power), and names it in at least min(0.80, the oracle's naming share).
// GYRO_LACK_OF_FIT_REALIZATIONS overrides the count per cell (docs/UNCERTAINTY.md's table: 200).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "compensation/fit_diagnostics.hpp"
#include "compensation/model_choice.hpp"
#include "noise_sim.hpp"

namespace station::test::noise {
namespace {

constexpr double kB0 = 0.02, kK1 = 1.5e-4, kK0 = 5.5e-3, kK2 = 1e-5, kKr = 0.004;

using Row = NoiseRow;
constexpr const auto& kRows = kNoiseRows;

using Extra = std::function<double(const compensation::ModelData&, std::size_t)>;

struct Case {
  const char* missing;  ///< the option the warning must name; "" for none
  Extra extra;          ///< the missing term's contribution at bin i
  compensation::Term term = compensation::Term::dT2;
  double size = 0;  ///< its coefficient
};

/// The norm of what the paper model leaves of a term: its residual after least squares on the
/// model's columns.
double unexplained(const compensation::ModelData& d, const Extra& f) {
  const Eigen::MatrixXd x = compensation::design_matrix(d.view(), {});
  Eigen::VectorXd v(x.rows());
  for (Eigen::Index i = 0; i < x.rows(); ++i) v(i) = f(d, static_cast<std::size_t>(i));
  return (v - x * x.colPivHouseholderQr().solve(v)).norm();
}

std::vector<Case> cases(const compensation::ModelData& d) {
  const auto dt = [](const compensation::ModelData& m, std::size_t i) { return m.temp_c[i] - 25; };
  const Extra k2 = [dt](const auto& m, std::size_t i) { return kK2 * std::pow(dt(m, i), 2); };
  const Extra cube = [dt](const auto& m, std::size_t i) { return std::pow(dt(m, i), 3); };
  const Extra cross = [dt](const auto& m, std::size_t i) { return m.grad_c[i] * dt(m, i); };
  const double k3 = unexplained(d, k2) / unexplained(d, cube);
  const double kg = unexplained(d, k2) / unexplained(d, cross);
  using compensation::Term;
  return {{"", [](const auto&, std::size_t) { return 0.0; }},
          {"dT2", k2, Term::dT2, kK2},
          {"dT3", [=](const auto& m, std::size_t i) { return k3 * cube(m, i); }, Term::dT3, k3},
          {"dTdt", [](const auto& m, std::size_t i) { return kKr * m.dtdt_c_per_h[i]; }, Term::dTdt,
           kKr},
          {"gradTdT", [=](const auto& m, std::size_t i) { return kg * cross(m, i); }, Term::gradTdT,
           kg}};
}

int realizations(bool null_case) {
  const char* env = std::getenv("GYRO_LACK_OF_FIT_REALIZATIONS");
  return env != nullptr ? std::max(20, std::atoi(env)) : null_case ? 100 : 60;
}

/// The inverse covariance of the bins' noise, from `draws` realizations of the noise alone:
/// (draws - p - 2) / (draws - 1) S^-1 is unbiased for Sigma^-1 (S the sample covariance of p
/// bins, mean known to be 0: Anderson, An Introduction to Multivariate Statistical Analysis,
/// 3rd ed., 2003, sec. 7.2, with draws degrees of freedom).
Eigen::MatrixXd noise_precision(const compensation::ModelData& design, const Levels& lv) {
  constexpr int kDraws = 1000;
  const auto n = static_cast<Eigen::Index>(design.bias_dph.size());
  std::mt19937_64 rng(77);
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(n, n);
  for (int r = 0; r < kDraws; ++r) {
    compensation::ModelData d = design;
    std::fill(d.bias_dph.begin(), d.bias_dph.end(), 0.0);
    add_noise(d, lv, rng);
    const Eigen::Map<const Eigen::VectorXd> e(d.bias_dph.data(), n);
    s.selfadjointView<Eigen::Lower>().rankUpdate(e, 1.0 / kDraws);
  }
  s = s.selfadjointView<Eigen::Lower>();
  return (kDraws - static_cast<double>(n) - 2) / kDraws * s.inverse();
}

/// The oracle's GLS z of each candidate in the model extended by it alone, under `precision`.
std::vector<double> oracle_z(const compensation::ModelData& d, const Eigen::MatrixXd& precision) {
  using compensation::Term;
  std::vector<double> z;
  const Eigen::Map<const Eigen::VectorXd> y(d.bias_dph.data(),
                                            static_cast<Eigen::Index>(d.bias_dph.size()));
  for (const Term t : {Term::dT2, Term::dT3, Term::dTdt, Term::gradTdT}) {
    compensation::ModelSpec spec;
    spec.terms.push_back(t);
    const Eigen::MatrixXd x = compensation::design_matrix(d.view(), spec);
    const Eigen::MatrixXd cov = (x.transpose() * precision * x).inverse();
    const Eigen::VectorXd b = cov * (x.transpose() * (precision * y));
    const Eigen::Index k = x.cols() - 1;
    z.push_back(b(k) / std::sqrt(cov(k, k)));
  }
  return z;
}

/// The option the oracle names: the candidate of largest |z| beyond z_crit ("" for none).
std::string oracle_named(const compensation::ModelData& d, const Eigen::MatrixXd& precision,
                         double z_crit) {
  const std::vector<double> z = oracle_z(d, precision);
  const char* const options[] = {"dT2", "dT3", "dTdt", "gradTdT"};
  std::string best;
  double largest = z_crit;
  for (std::size_t k = 0; k < z.size(); ++k)
    if (std::abs(z[k]) > largest) largest = std::abs(z[k]), best = options[k];
  return best;
}

/// Power of the oracle test: the candidate's GLS z, N(delta, 1), beyond +-z_crit.
double oracle_power(const compensation::ModelData& design, const Eigen::MatrixXd& precision,
                    const Case& c, double z_crit) {
  compensation::ModelSpec spec;
  spec.terms.push_back(c.term);
  const Eigen::MatrixXd x = compensation::design_matrix(design.view(), spec);
  const Eigen::MatrixXd cov = (x.transpose() * precision * x).inverse();
  const double delta = c.size / std::sqrt(cov(x.cols() - 1, x.cols() - 1));
  return 0.5 * (std::erfc((z_crit - delta) / std::sqrt(2.0)) +
                std::erfc((z_crit + delta) / std::sqrt(2.0)));
}

/// Whether the fit finds candidate `option` significant (its ratio beyond the bound).
bool significant(const compensation::FitResult& fit, const std::string& option) {
  for (const auto& c : fit.candidates)
    if (c.option == option) return c.significant;
  return false;
}

/// The option a fit's lack-of-fit warning names ("" when it warns of none).
std::string named(const compensation::FitResult& fit) {
  for (const auto& w : fit.warnings) {
    const std::string key = "missing term ";
    if (const auto at = w.find(key); at != std::string::npos)
      return w.substr(at + key.size(), w.find(':', at) - at - key.size());
  }
  return "";
}

/// Shares of realizations whose fit, and the oracle, name `c.missing` (or, for the null case,
/// name anything); and whose fit finds c.missing significant, named or not.
struct Shares {
  double station = 0, oracle = 0, significant = 0;
};

Shares shares_named(const compensation::ModelData& design, const Case& c, const Levels& lv,
                    const Eigen::MatrixXd& precision, double z_crit, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  int hits = 0, oracle_hits = 0, found = 0;
  const int n = realizations(*c.missing == 0);
  const auto hit = [&c](const std::string& said) {
    return std::string(c.missing).empty() ? !said.empty() : said == c.missing;
  };
  for (int r = 0; r < n; ++r) {
    compensation::ModelData d = design;
    for (std::size_t i = 0; i < d.bias_dph.size(); ++i)
      d.bias_dph[i] = kB0 + kK1 * (d.temp_c[i] - 25) + kK0 * d.grad_c[i] + c.extra(design, i);
    add_noise(d, lv, rng);
    const compensation::FitResult fit = compensation::fit_model(d.view(), {});
    hits += hit(named(fit));
    found += significant(fit, c.missing);
    oracle_hits += hit(oracle_named(d, precision, z_crit));
  }
  return {static_cast<double>(hits) / n, static_cast<double>(oracle_hits) / n,
          static_cast<double>(found) / n};
}

TEST(LackOfFit, NamesAMissingTermUnderEveryNoiseAndRarelyWarnsWithoutOne) {
  const compensation::ModelData design = protocols_bins({Protocol{}});
  constexpr double kZCrit = 3.0233;  // 1 % family-wise over the 4 candidates (fit_diagnostics)
  std::uint64_t seed = 3200;
  for (const Row& row : kRows) {
    const Eigen::MatrixXd precision = noise_precision(design, row.levels);
    std::string line = std::string("| ") + row.name;
    for (const Case& c : cases(design)) {
      const Shares got = shares_named(design, c, row.levels, precision, kZCrit, seed++);
      const double s = got.station;
      const int n = realizations(*c.missing == 0);
      SCOPED_TRACE(std::string(row.name) + ", missing " + (*c.missing ? c.missing : "nothing"));
      // One-sided binomial slack at 1 %: 2.33 sd of a share of n at the bound.
      const auto slack = [n](double p) { return 2.33 * std::sqrt(p * (1 - p) / n); };
      char cell[48];
      if (*c.missing == 0) {
        std::snprintf(cell, sizeof cell, " | %.2f (%.2f)", s, got.oracle);
        EXPECT_LE(s, 0.10 + slack(0.10)) << "false alarms";
      } else {
        // Named: 80 %, or what the oracle names on the same realizations where that is less.
        // Found significant: 80 %, or the oracle's power where that is less.
        const double power = oracle_power(design, precision, c, kZCrit);
        const double goal = std::min(0.80, got.oracle), found_goal = std::min(0.80, power);
        std::snprintf(cell, sizeof cell, " | %.2f [%.2f] (%.2f; %.2f)", s, got.significant, power,
                      got.oracle);
        EXPECT_GE(got.significant, found_goal - slack(found_goal))
            << "found too rarely; the oracle's power " << power;
        EXPECT_GE(s, goal - slack(goal)) << "named too rarely; the oracle names it in "
                                         << got.oracle << " (power " << power << ")";
      }
      line += cell;
    }
    std::printf("%s |\n", line.c_str());
  }
}

}  // namespace
}  // namespace station::test::noise

namespace station::test::noise {
namespace {

// model_choice.cpp refines a candidate's error-model search only when its ratio comes within
// kRefinementGain (3) of the bound. Evidence for that shortcut: with every candidate refined
// the decisions are the same, and no refinement gains more than the margin (measured: 2.07
// over 700 fits when it was chosen).
TEST(LackOfFit, RefiningOnlyNearTheBoundChangesNoDecision) {
  const compensation::ModelData design = protocols_bins({Protocol{}});
  const auto all = cases(design);
  std::mt19937_64 rng(3300);
  const double bound = 3.0233 * 3.0233;
  double largest_gain = 0;
  for (int r = 0; r < 40; ++r) {
    const Case& c = all[static_cast<std::size_t>(r) % all.size()];
    compensation::ModelData d = design;
    for (std::size_t i = 0; i < d.bias_dph.size(); ++i)
      d.bias_dph[i] = kB0 + kK1 * (d.temp_c[i] - 25) + kK0 * d.grad_c[i] + c.extra(design, i);
    add_noise(d, kNoiseRows[static_cast<std::size_t>(r) % std::size(kNoiseRows)].levels, rng);
    const compensation::ModelSpec base;
    const auto tried = compensation::candidates_for(d.view(), base);
    const auto quick = compensation::extension_likelihood_ratios(d.view(), base, tried, bound);
    const auto full = compensation::extension_likelihood_ratios(d.view(), base, tried, -INFINITY);
    for (std::size_t k = 0; k < tried.size(); ++k) {
      EXPECT_EQ(quick[k] > bound, full[k] > bound) << "realization " << r << ", candidate " << k;
      largest_gain = std::max(largest_gain, full[k] - quick[k]);
    }
  }
  std::printf("largest gain of refining every candidate: %.2f\n", largest_gain);
  EXPECT_LT(largest_gain, 3.0);
}

}  // namespace
}  // namespace station::test::noise
