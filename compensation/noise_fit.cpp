// The IEEE 952 noise terms fitted to the whole Allan-variance curve (allan.hpp, fit_noise_terms).
#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "compensation/allan.hpp"

namespace station::compensation {
namespace {

constexpr int kTerms = 4;  // Q, N, B, K
// Basis of sigma^2(tau) for theta = (Q^2, N^2, B^2, K^2), rate in deg/h and tau in s
// (1 (deg/h) s = 1 arcsec; IEEE 952 Table C.2): 3 Q^2/tau^2; (60 N)^2/tau with N in deg/sqrt(h);
// (2 ln 2 / pi) B^2; K^2 tau / (3 * 3600) with K in deg/h/sqrt(h).
std::array<double, kTerms> basis(double tau_s) {
  return {3.0 / (tau_s * tau_s), 3600.0 / tau_s, 2.0 * std::numbers::ln2 / std::numbers::pi,
          tau_s / (3.0 * 3600.0)};
}

struct SubsetFit {
  std::array<double, kTerms> theta{};
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  double chi2 = std::numeric_limits<double>::infinity();
  bool feasible = false;
};

/// Weighted fit of the terms in `mask` with weights w; infeasible when a theta comes out < 0.
SubsetFit fit_subset(const std::vector<AdevPoint>& pts, const std::vector<double>& w, int mask) {
  std::array<int, kTerms> idx{};
  int k = 0;
  for (int j = 0; j < kTerms; ++j)
    if (mask & (1 << j)) idx[k++] = j;
  SubsetFit out;
  if (static_cast<int>(pts.size()) <= k) return out;
  Eigen::MatrixXd a(pts.size(), k);
  Eigen::VectorXd y(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto b = basis(pts[i].tau_s);
    const double sw = std::sqrt(w[i]);
    for (int c = 0; c < k; ++c) a(static_cast<Eigen::Index>(i), c) = sw * b[idx[c]];
    y(static_cast<Eigen::Index>(i)) = sw * pts[i].adev * pts[i].adev;
  }
  const Eigen::MatrixXd ata = a.transpose() * a;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(ata);
  if (ldlt.info() != Eigen::Success) return out;
  const Eigen::VectorXd th = ldlt.solve(a.transpose() * y);
  const Eigen::MatrixXd cov = ldlt.solve(Eigen::MatrixXd::Identity(k, k));
  out.feasible = th.allFinite();
  for (int c = 0; c < k; ++c) {
    out.feasible = out.feasible && th(c) >= 0;
    out.theta[idx[c]] = th(c);
    for (int d = 0; d < k; ++d) out.cov(idx[c], idx[d]) = cov(c, d);
  }
  out.chi2 = (y - a * th).squaredNorm();
  return out;
}

/// The best feasible subset under weights w (the non-negative least-squares solution).
SubsetFit best_fit(const std::vector<AdevPoint>& pts, const std::vector<double>& w) {
  SubsetFit best;
  for (int mask = 1; mask < (1 << kTerms); ++mask) {
    SubsetFit f = fit_subset(pts, w, mask);
    if (f.feasible && f.chi2 < best.chi2) best = f;
  }
  return best;
}

double model_var(const std::array<double, kTerms>& theta, double tau_s) {
  const auto b = basis(tau_s);
  double v = 0;
  for (int j = 0; j < kTerms; ++j) v += theta[j] * b[j];
  return v;
}

}  // namespace

NoiseTerms fit_noise_terms(std::span<const AdevPoint> curve) {
  std::vector<AdevPoint> pts;
  for (const auto& p : curve)
    if (p.tau_s > 0 && p.adev > 0 && std::isfinite(p.adev) && p.edf >= 1) pts.push_back(p);
  NoiseTerms out;
  if (pts.size() < 2) return out;
  // Var(AVAR estimate) = 2 sigma^4 / edf; sigma from the model once there is one (iterated
  // weights: the estimate's own scatter would favour the points that came out low).
  std::vector<double> w(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) w[i] = pts[i].edf / (2.0 * std::pow(pts[i].adev, 4));
  SubsetFit fit = best_fit(pts, w);
  for (int iter = 0; iter < 5 && fit.feasible; ++iter) {
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double v = model_var(fit.theta, pts[i].tau_s);
      if (v > 0) w[i] = pts[i].edf / (2.0 * v * v);
    }
    fit = best_fit(pts, w);
  }
  if (!fit.feasible) return out;
  int used = 0;
  for (const double t : fit.theta) used += t > 0 ? 1 : 0;
  const int dof = static_cast<int>(pts.size()) - used;
  const double chi2_dof = dof > 0 ? fit.chi2 / dof : 1.0;
  out.fit_chi2_per_dof = chi2_dof;
  const double inflate = std::max(1.0, chi2_dof);  // never narrower than the points allow
  const auto term = [&](int j, double scale, std::optional<double>& value,
                        std::optional<double>& se) {
    if (!(fit.theta[j] > 0)) return;
    const double c = std::sqrt(fit.theta[j]);
    value = c / scale;
    se = std::sqrt(fit.cov(j, j) * inflate) / (2.0 * c) / scale;
  };
  term(0, 1.0, out.quantization_arcsec, out.quantization_se);
  term(1, 1.0, out.angle_random_walk_deg_rth, out.angle_random_walk_se);
  term(2, 1.0, out.bias_instability_dph, out.bias_instability_se);
  term(3, 1.0, out.rate_random_walk_dph_rth, out.rate_random_walk_se);
  if (out.bias_instability_dph) {
    // Where the curve is flattest: the minimum of the fitted curve over the measured taus.
    double best = std::numeric_limits<double>::infinity();
    for (const auto& p : pts) {
      const double v = model_var(fit.theta, p.tau_s);
      if (v < best) {
        best = v;
        out.bias_instability_tau_s = p.tau_s;
      }
    }
  }
  return out;
}

double noise_model_adev(const NoiseTerms& t, double tau_s) {
  const auto sq = [](const std::optional<double>& v) { return v ? *v * *v : 0.0; };
  return std::sqrt(model_var({sq(t.quantization_arcsec), sq(t.angle_random_walk_deg_rth),
                              sq(t.bias_instability_dph), sq(t.rate_random_walk_dph_rth)},
                             tau_s));
}

}  // namespace station::compensation
