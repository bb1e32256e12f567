// The error model's two computations against the textbook dense forms on small problems: the
// restricted likelihood by the Kalman filter (compensation/reml_filter.hpp, four models to a pass)
// and the sandwich variances formed in O(n p) (correlated_errors.hpp), each against an explicit
// n x n covariance and Cholesky factorizations (Harville 1977, JASA 72:320, eq. for the REML
// log-likelihood; Greene, Econometric Analysis, eq. 9-9, for the sandwich).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "compensation/correlated_errors.hpp"
#include "compensation/reml_filter.hpp"

namespace sc = station::compensation;

namespace {

// Two runs at irregular times: 23 bins, then 17 (s since each run's start differ).
struct Problem {
  std::vector<double> t_s;
  std::vector<int> segment;
  std::vector<double> dt_h;  // hours from the previous bin, -1 where a run starts
  Eigen::MatrixXd x;
  Eigen::VectorXd y;
};

Problem make_problem(int p, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> gap(400, 800);
  std::normal_distribution<double> g;
  Problem pb;
  for (int run = 0; run < 2; ++run) {
    double t = 1000.0 * run;
    for (int i = 0; i < (run == 0 ? 23 : 17); ++i) {
      pb.dt_h.push_back(i == 0 ? -1.0 : 0.0);
      const double step = i == 0 ? 0.0 : gap(rng);
      t += step;
      if (i > 0) pb.dt_h.back() = step / 3600;
      pb.t_s.push_back(t);
      pb.segment.push_back(run);
    }
  }
  const auto n = static_cast<Eigen::Index>(pb.t_s.size());
  pb.x.resize(n, p);
  for (Eigen::Index i = 0; i < n; ++i) {
    pb.x(i, 0) = 1;
    for (int j = 1; j < p; ++j) pb.x(i, j) = std::sin(0.3 * j * static_cast<double>(i)) + g(rng);
  }
  pb.y.resize(n);
  double walk = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    walk = pb.dt_h[static_cast<std::size_t>(i)] < 0 ? 0 : walk + 0.5 * g(rng);
    pb.y(i) = 0.3 + walk + g(rng);
  }
  return pb;
}

// C in units of s^2: (1 - q) I + q exp(-|t_i - t_j| / tau) + w min(h_i, h_j), within a run.
Eigen::MatrixXd dense_cov(const Problem& pb, double tau_s, double q, double w_per_h) {
  const auto n = static_cast<Eigen::Index>(pb.t_s.size());
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  std::vector<double> h(pb.t_s.size());
  for (std::size_t i = 0; i < h.size(); ++i) h[i] = pb.dt_h[i] < 0 ? 0 : h[i - 1] + pb.dt_h[i];
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const auto iu = static_cast<std::size_t>(i), ju = static_cast<std::size_t>(j);
      if (pb.segment[iu] != pb.segment[ju]) continue;
      c(i, j) = (i == j ? 1 - q : 0.0) +
                (q > 0 ? q * std::exp(-std::abs(pb.t_s[iu] - pb.t_s[ju]) / tau_s) : 0.0) +
                w_per_h * std::min(h[iu], h[ju]);
    }
  return c;
}

// -2 restricted log-likelihood with b and s^2 concentrated out, constants dropped:
// log|C| + log|X' C^-1 X| + (n - p) log s^2, s^2 = y' P y / (n - p).
double dense_reml(const Problem& pb, double tau_s, double q, double w_per_h) {
  const Eigen::LLT<Eigen::MatrixXd> llt(dense_cov(pb, tau_s, q, w_per_h));
  const Eigen::MatrixXd ci_x = llt.solve(pb.x);
  const Eigen::VectorXd ci_y = llt.solve(pb.y);
  const Eigen::MatrixXd xcx = pb.x.transpose() * ci_x;
  const Eigen::LLT<Eigen::MatrixXd> llt_x(xcx);
  const Eigen::VectorXd b = llt_x.solve(pb.x.transpose() * ci_y);
  const double dof = static_cast<double>(pb.x.rows() - pb.x.cols());
  const double s2 = (pb.y.dot(ci_y) - (pb.x.transpose() * ci_y).dot(b)) / dof;
  auto logdet = [](const Eigen::LLT<Eigen::MatrixXd>& l) {
    return 2 * l.matrixL().toDenseMatrix().diagonal().array().log().sum();
  };
  return logdet(llt) + logdet(llt_x) + dof * std::log(s2);
}

std::vector<double> step_corr(const Problem& pb, double tau_s) {
  std::vector<double> phi(pb.t_s.size(), 0.0);
  for (std::size_t i = 1; i < phi.size(); ++i)
    if (pb.dt_h[i] >= 0) phi[i] = std::exp(-(pb.t_s[i] - pb.t_s[i - 1]) / tau_s);
  return phi;
}

}  // namespace

// Seven models (one pass of four and one of three lanes) at p = 3 and at the filter's widest,
// p = 9: each -2 l_R equals the dense one to 1e-9 relative (the filter and the Cholesky differ
// only in rounding; the sums are of order 100).
TEST(CorrelatedErrors, KalmanRemlEqualsTheDenseRestrictedLikelihood) {
  struct M {
    double tau_s, q, w_per_h;
  };
  const M models[] = {{1e9, 0, 0},      {1500, 0.4, 0},      {9000, 0.9, 0},   {300, 0.2, 0.3},
                      {4000, 0.0, 2.0}, {60000, 0.99, 0.01}, {2500, 0.6, 0.05}};
  for (int p : {3, 9}) {
    const Problem pb = make_problem(p, 11 + p);
    sc::reml::RowMajor z(pb.x.rows(), p + 1);
    z.col(0) = pb.y;
    z.rightCols(p) = pb.x;
    std::vector<std::vector<double>> phis;
    for (const M& m : models) phis.push_back(step_corr(pb, m.tau_s));
    std::vector<sc::reml::Model> in;
    for (std::size_t i = 0; i < std::size(models); ++i)
      in.push_back({&phis[i], models[i].q, models[i].w_per_h});
    std::vector<sc::reml::Profile> out(in.size());
    sc::reml::profiles(z, pb.dt_h, in, out);
    for (std::size_t i = 0; i < std::size(models); ++i) {
      const double dense = dense_reml(pb, models[i].tau_s, models[i].q, models[i].w_per_h);
      EXPECT_NEAR(out[i].minus2_loglik, dense, 1e-9 * std::abs(dense))
          << "p " << p << " model " << i;
    }
  }
}

// The O(n p) sandwich s^2 R^-1 Q' C Q R^-T against the dense (X'X)^-1 X' C X (X'X)^-1, for one
// model and for a mixture (the weighted geometric mean of the components' variances).
TEST(CorrelatedErrors, SandwichVariancesEqualTheDenseForm) {
  const Problem pb = make_problem(4, 5);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(pb.x);
  const auto p = pb.x.cols();
  const Eigen::MatrixXd r = qr.matrixQR().topLeftCorner(p, p).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inv = r.inverse();
  const Eigen::MatrixXd q_basis = qr.householderQ() * Eigen::MatrixXd::Identity(pb.x.rows(), p);
  const Eigen::MatrixXd xtx_inv = (pb.x.transpose() * pb.x).inverse();
  auto dense = [&](double tau_s, double q, double s_dph, double rrw) {
    const Eigen::MatrixXd c = dense_cov(pb, tau_s, q, std::pow(rrw / s_dph, 2));
    return Eigen::VectorXd((xtx_inv * pb.x.transpose() * c * pb.x * xtx_inv).diagonal() * s_dph *
                           s_dph);
  };
  sc::ErrorModel one;
  one.corr_time_s = 2500;
  one.correlated_share = 0.6;
  one.sigma_dph = 0.007;
  one.rrw_dph_per_sqrt_h = 0.002;
  const Eigen::VectorXd v1 = sc::ols_variances_under(one, q_basis, r_inv, pb.t_s, pb.segment);
  const Eigen::VectorXd d1 = dense(2500, 0.6, 0.007, 0.002);
  for (Eigen::Index j = 0; j < p; ++j) EXPECT_NEAR(v1(j) / d1(j), 1.0, 1e-10) << "term " << j;

  sc::ErrorModel mix = one;
  mix.mixture = {
      {2500, 0.6, 0.007, 0.002, 1.0}, {800, 0.3, 0.008, 0.0, 0.5}, {0, 0, 0.009, 0.001, 0.25}};
  const Eigen::VectorXd vm = sc::ols_variances_under(mix, q_basis, r_inv, pb.t_s, pb.segment);
  const Eigen::VectorXd d2 = dense(800, 0.3, 0.008, 0.0), d3 = dense(1, 0, 0.009, 0.001);
  for (Eigen::Index j = 0; j < p; ++j) {
    const double geo =
        std::exp((1.0 * std::log(d1(j)) + 0.5 * std::log(d2(j)) + 0.25 * std::log(d3(j))) / 1.75);
    EXPECT_NEAR(vm(j) / geo, 1.0, 1e-10) << "term " << j;
  }
}
