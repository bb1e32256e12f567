// The Kalman pass of the error model (compensation/reml_filter.hpp): a model's likelihoods are
// the same bits whichever pass computes them — alone (four lanes, SSE2 or AVX2), among eight
// (AVX-512 where the CPU has it, issue 37) or in another lane — so no fit depends on the machine
// or on how many models a search asks at once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "compensation/reml_filter.hpp"

namespace station::compensation::reml {
namespace {

struct Case {
  RowMajor z;
  std::vector<double> dt_h;
  std::vector<std::vector<double>> phis;
  std::vector<Model> models;
};

// y with a trend and noise, a constant, two regressors, then four candidates; 10-minute bins in
// two runs; 13 models (one wide pass of eight and one of five lanes).
Case make_case(Eigen::Index n, std::uint64_t seed) {
  Case c;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  c.z.resize(n, 8);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(n);
    c.z.row(i) << 0.3 * t + g(rng), 1.0, t, std::sin(9.0 * t), g(rng), t * t, g(rng), std::cos(t);
  }
  c.dt_h.assign(static_cast<std::size_t>(n), 1.0 / 6.0);
  c.dt_h[0] = c.dt_h[static_cast<std::size_t>(n / 2)] = -1;
  for (const double tau_s : {300.0, 3000.0, 30000.0}) {
    c.phis.emplace_back(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < c.phis.back().size(); ++i)
      c.phis.back()[i] = c.dt_h[i] < 0 ? 0.0 : std::exp(-600.0 / tau_s);
  }
  for (const auto& phi : c.phis)
    for (const double q : {0.0, 0.5})
      for (const double w : {0.0, 0.02}) c.models.push_back({&phi, q, w});
  c.models.push_back({&c.phis[1], 0.99, 1.0});
  return c;
}

}  // namespace

TEST(RemlFilter, EachModelTheSameBitsAloneAndInAWidePass) {
  const Case c = make_case(1001, 3);
  const std::size_t k = c.models.size();
  std::vector<Profile> all(k);
  std::vector<Deviances> all_ml(k);
  evaluate(c.z, 3, c.dt_h, c.models, all, all_ml);
  // The same models in reverse order: every model in another lane of another pass.
  std::vector<Model> reversed(c.models.rbegin(), c.models.rend());
  std::vector<Profile> back(k);
  std::vector<Deviances> back_ml(k);
  evaluate(c.z, 3, c.dt_h, reversed, back, back_ml);
  // The restricted likelihood from a pass over the base columns alone (four columns).
  const RowMajor base_z = c.z.leftCols(4);
  std::vector<Profile> base_all(k);
  evaluate(base_z, 3, c.dt_h, c.models, base_all);
  for (std::size_t i = 0; i < k; ++i) {
    std::vector<Profile> one(1);
    std::vector<Deviances> one_ml(1);
    evaluate(c.z, 3, c.dt_h, std::span(c.models).subspan(i, 1), one, one_ml);
    ASSERT_TRUE(std::isfinite(one[0].minus2_loglik)) << i;
    EXPECT_EQ(all[i].minus2_loglik, one[0].minus2_loglik) << i;
    EXPECT_EQ(all[i].sigma2, one[0].sigma2) << i;
    EXPECT_EQ(back[k - 1 - i].minus2_loglik, one[0].minus2_loglik) << i;
    for (std::size_t d = 0; d < one_ml[0].size(); ++d) {
      EXPECT_EQ(all_ml[i][d], one_ml[0][d]) << i << " deviance " << d;
      EXPECT_EQ(back_ml[k - 1 - i][d], one_ml[0][d]) << i << " deviance " << d;
    }
    std::vector<Profile> base_one(1);
    evaluate(base_z, 3, c.dt_h, std::span(c.models).subspan(i, 1), base_one);
    EXPECT_EQ(base_one[0].minus2_loglik, one[0].minus2_loglik) << i;
    EXPECT_EQ(base_all[i].minus2_loglik, one[0].minus2_loglik) << i;
  }
}

}  // namespace station::compensation::reml
