// The IEEE 952 noise terms fitted to the whole Allan-variance curve (allan.hpp, fit_noise_terms).
//
// The estimate is weighted least squares on AVAR (weights edf / (2 sigma^4), the model's sigma
// iterated; non-negative squares by the best feasible subset): unbiased, but the overlapping
// estimates at different taus share the same data and are strongly correlated (0.5 to 0.75
// between neighbouring octaves), so the WLS covariance (A'WA)^-1, which treats them as
// independent, is too narrow: an independent review (30 realizations of 2e6 s) found +-1 SE
// covering N, B, K 0.63 / 0.47 / 0.48 of the time. The standard errors are therefore the
// sandwich (Huber 1967; White 1980, Econometrica 48, eq. 3; for any linear estimator
// theta = H y, Cov(theta) = H S H'):
//   Cov(theta) = (A'WA)^-1 A'W S W A (A'WA)^-1,
// with S the model covariance of the correlated AVAR estimates at the fitted terms
// (noise_fit_cov.hpp). The estimate itself is unchanged.
//
// Quantization Q is kept only when Q^2 is above 0 at the one-sided 1 % level under that
// covariance, theta_Q / se(theta_Q) >= 2.326 (a test on theta = Q^2: the delta method for Q is
// singular at Q = 0); otherwise the other terms are refit without it. The test uses the model
// covariance, not the residuals, so an exact curve (chi^2 = 0) is judged by its edf like any
// other. N, B and K are not tested: tried on all four, it dropped a real K in 28 of 30
// realizations of the review's gyro (its K^2 is under 2 of its se) and biased N and B through
// the misfit.
//
// The fit's chi^2 is the generalized one, r' S^-1 r over its expectation under the model,
// tr(S^-1 P S P') with P = I - A (A'WA)^-1 A'W (E[r'Mr] = tr(M E[rr']) for a zero-mean r;
// Searle, Linear Models, 1971, §2.5): 1 on average when the terms explain the curve, n - k in
// the denominator when S = W^-1. When it is above 1 the errors are scaled up by its square root.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include "compensation/allan.hpp"
#include "compensation/noise_fit_cov.hpp"

namespace station::compensation {
namespace {

constexpr int kTerms = 4;  // Q, N, B, K
constexpr int kAllTerms = (1 << kTerms) - 1;
constexpr double kPresenceZ = 2.3263478740408408;  // one-sided 1 % point of N(0, 1)
// At most 4 points per octave enter the fit: denser points (TauSpacing::all) add little beyond
// their correlated neighbours and the covariance costs a pair of points each.
const double kMinTauRatio = std::pow(2.0, 0.25);

// Basis of sigma^2(tau) for theta = (Q^2, N^2, B^2, K^2), rate in deg/h and tau in s
// (1 (deg/h) s = 1 arcsec; IEEE 952 Table C.2): 3 Q^2/tau^2; (60 N)^2/tau with N in deg/sqrt(h);
// (2 ln 2 / pi) B^2; K^2 tau / (3 * 3600) with K in deg/h/sqrt(h).
std::array<double, kTerms> basis(double tau_s) {
  return {3.0 / (tau_s * tau_s), 3600.0 / tau_s, 2.0 * std::numbers::ln2 / std::numbers::pi,
          tau_s / (3.0 * 3600.0)};
}

double model_var(const NoiseTheta& theta, double tau_s) {
  const auto b = basis(tau_s);
  double v = 0;
  for (int j = 0; j < kTerms; ++j) v += theta[j] * b[j];
  return v;
}

struct Curve {
  std::vector<AdevPoint> pts;
  Eigen::VectorXd avar;               // the estimates, (deg/h)^2
  std::optional<AvarCovariance> cov;  // empty: points without m, n (e.g. an exact curve)
};

struct SubsetFit {
  NoiseTheta theta{};
  int mask = 0;
  std::vector<double> w;                                  // the weights of the fit
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();          // sandwich covariance of theta
  double chi2 = std::numeric_limits<double>::infinity();  // weighted, for the NNLS choice
  bool feasible = false;
};

// Design matrix of the terms in `mask`, one row per point.
Eigen::MatrixXd design(const Curve& c, int mask) {
  Eigen::MatrixXd a(static_cast<Eigen::Index>(c.pts.size()), std::popcount(unsigned(mask)));
  for (std::size_t i = 0; i < c.pts.size(); ++i) {
    const auto b = basis(c.pts[i].tau_s);
    Eigen::Index col = 0;
    for (int j = 0; j < kTerms; ++j)
      if (mask & (1 << j)) a(static_cast<Eigen::Index>(i), col++) = b[j];
  }
  return a;
}

Eigen::VectorXd as_vector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

/// Weighted fit of the terms in `mask` with weights w; infeasible when a theta comes out < 0.
SubsetFit fit_subset(const Curve& c, const std::vector<double>& w, int mask) {
  SubsetFit out;
  out.mask = mask;
  out.w = w;
  const Eigen::MatrixXd a = design(c, mask);
  if (a.rows() <= a.cols()) return out;
  const Eigen::VectorXd wv = as_vector(w);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(a.transpose() * wv.asDiagonal() * a);
  if (ldlt.info() != Eigen::Success) return out;
  const Eigen::VectorXd th = ldlt.solve(a.transpose() * wv.asDiagonal() * c.avar);
  out.feasible = th.allFinite();
  Eigen::Index col = 0;
  for (int j = 0; j < kTerms; ++j) {
    if (!(mask & (1 << j))) continue;
    out.feasible = out.feasible && th(col) >= 0;
    out.theta[j] = th(col++);
  }
  const Eigen::VectorXd r = c.avar - a * th;
  out.chi2 = r.dot(wv.asDiagonal() * r);
  return out;
}

/// The best feasible subset of `allowed` under weights w (the non-negative least-squares fit).
SubsetFit best_fit(const Curve& c, const std::vector<double>& w, int allowed) {
  SubsetFit best;
  for (int mask = 1; mask <= kAllTerms; ++mask) {
    if ((mask & ~allowed) != 0) continue;
    SubsetFit f = fit_subset(c, w, mask);
    if (f.feasible && f.chi2 < best.chi2) best = std::move(f);
  }
  return best;
}

// Var(AVAR estimate) = 2 sigma^4 / edf (chi-squared with the point's Greenhall edf); sigma from
// the model once there is one (iterated weights: the estimate's own scatter would favour the
// points that came out low).
SubsetFit iterated_fit(const Curve& c, int allowed) {
  std::vector<double> w(c.pts.size());
  for (std::size_t i = 0; i < c.pts.size(); ++i)
    w[i] = c.pts[i].edf / (2.0 * std::pow(c.pts[i].adev, 4));
  SubsetFit fit = best_fit(c, w, allowed);
  for (int iter = 0; iter < 5 && fit.feasible; ++iter) {
    for (std::size_t i = 0; i < c.pts.size(); ++i) {
      const double v = model_var(fit.theta, c.pts[i].tau_s);
      if (v > 0) w[i] = c.pts[i].edf / (2.0 * v * v);
    }
    fit = best_fit(c, w, allowed);
  }
  return fit;
}

// The covariance of the AVAR estimates at theta: the correlated model when the points carry
// m and n, else independent points with variance 2 sigma^4 / edf.
Eigen::MatrixXd model_cov(const Curve& c, const NoiseTheta& theta) {
  if (c.cov) return c.cov->at(theta);
  Eigen::VectorXd d(static_cast<Eigen::Index>(c.pts.size()));
  for (std::size_t i = 0; i < c.pts.size(); ++i) {
    const double v = model_var(theta, c.pts[i].tau_s);
    d(static_cast<Eigen::Index>(i)) = 2.0 * v * v / c.pts[i].edf;
  }
  return d.asDiagonal();
}

// Sandwich (A'WA)^-1 A'W S W A (A'WA)^-1 of the fit's terms, spread into the 4 x 4 matrix.
void set_sandwich(const Curve& c, const Eigen::MatrixXd& s, SubsetFit& f) {
  const Eigen::MatrixXd a = design(c, f.mask);
  const Eigen::MatrixXd wa = as_vector(f.w).asDiagonal() * a;
  const Eigen::MatrixXd bread = (a.transpose() * wa).inverse();
  const Eigen::MatrixXd cov = bread * (wa.transpose() * s * wa) * bread;
  std::array<int, kTerms> idx{};
  int k = 0;
  for (int j = 0; j < kTerms; ++j)
    if (f.mask & (1 << j)) idx[k++] = j;
  f.cov.setZero();
  for (int r = 0; r < k; ++r)
    for (int q = 0; q < k; ++q) f.cov(idx[r], idx[q]) = cov(r, q);
}

// r' S^-1 r over its expectation under the model, tr(S^-1 P S P') with P = I - A (A'WA)^-1 A'W
// (the WLS residual is r = P y, so E[r r'] = P S P'; with S = W^-1 the expectation is n - k, the
// usual chi^2 / dof). S is scaled to a correlation matrix before it is factored.
double chi2_ratio(const Curve& c, const Eigen::MatrixXd& s, const SubsetFit& f) {
  const Eigen::MatrixXd a = design(c, f.mask);
  const Eigen::Index n = a.rows(), k = a.cols();
  const double plain = f.chi2 / static_cast<double>(std::max<Eigen::Index>(1, n - k));
  Eigen::VectorXd th(k);
  for (int j = 0, col = 0; j < kTerms; ++j)
    if (f.mask & (1 << j)) th(col++) = f.theta[j];
  const Eigen::VectorXd r = c.avar - a * th;
  const Eigen::MatrixXd wa = as_vector(f.w).asDiagonal() * a;
  const Eigen::MatrixXd p =
      Eigen::MatrixXd::Identity(n, n) - a * (a.transpose() * wa).ldlt().solve(wa.transpose());
  if (!(s.diagonal().minCoeff() > 0)) return plain;
  const Eigen::VectorXd d = s.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::LDLT<Eigen::MatrixXd> corr(d.asDiagonal() * s * d.asDiagonal());
  if (corr.info() != Eigen::Success || !corr.isPositive()) return plain;
  const Eigen::VectorXd z = d.asDiagonal() * r;
  const Eigen::MatrixXd q = d.asDiagonal() * (p * s * p.transpose()) * d.asDiagonal();
  const double expected = corr.solve(q).trace();
  return expected > 0 ? z.dot(corr.solve(z)) / expected : plain;
}

// The fit of the terms in `allowed` with its sandwich covariance; s is set to the model
// covariance of the points at the fitted terms.
SubsetFit fit_with_cov(const Curve& c, int allowed, Eigen::MatrixXd& s) {
  SubsetFit f = iterated_fit(c, allowed);
  if (!f.feasible) return f;
  s = model_cov(c, f.theta);
  set_sandwich(c, s, f);
  return f;
}

// All terms, then without Q unless Q^2 is above 0 at the one-sided 1 % level (or is all there
// is). `ratio` is the generalized chi^2 of the final fit over its expectation.
SubsetFit select_terms(const Curve& c, double& ratio) {
  Eigen::MatrixXd s;
  SubsetFit f = fit_with_cov(c, kAllTerms, s);
  const bool weak_q = f.feasible && f.theta[0] > 0 && f.mask != 1 &&
                      !(f.theta[0] / std::sqrt(f.cov(0, 0)) >= kPresenceZ);
  if (weak_q) f = fit_with_cov(c, kAllTerms & ~1, s);
  if (f.feasible) ratio = chi2_ratio(c, s, f);
  return f;
}

// The usable points, by tau, at most 4 per octave, with their covariance model.
Curve usable_curve(std::span<const AdevPoint> curve) {
  std::vector<AdevPoint> pts;
  for (const auto& p : curve)
    if (p.tau_s > 0 && p.adev > 0 && std::isfinite(p.adev) && p.edf >= 1) pts.push_back(p);
  std::stable_sort(pts.begin(), pts.end(),
                   [](const AdevPoint& l, const AdevPoint& r) { return l.tau_s < r.tau_s; });
  Curve c;
  for (const auto& p : pts)
    if (c.pts.empty() || p.tau_s >= c.pts.back().tau_s * kMinTauRatio * (1 - 1e-12))
      c.pts.push_back(p);
  c.avar.resize(static_cast<Eigen::Index>(c.pts.size()));
  for (std::size_t i = 0; i < c.pts.size(); ++i)
    c.avar(static_cast<Eigen::Index>(i)) = c.pts[i].adev * c.pts[i].adev;
  c.cov = AvarCovariance::of(c.pts);
  return c;
}

// Where the fitted curve is flattest: its minimum over the measured taus.
double flattest_tau(const Curve& c, const NoiseTheta& theta) {
  double best = std::numeric_limits<double>::infinity(), tau = 0;
  for (const auto& p : c.pts) {
    const double v = model_var(theta, p.tau_s);
    if (v < best) best = v, tau = p.tau_s;
  }
  return tau;
}

}  // namespace

NoiseTerms fit_noise_terms(std::span<const AdevPoint> curve) {
  NoiseTerms out;
  const Curve c = usable_curve(curve);
  if (c.pts.size() < 2) return out;
  double ratio = 1.0;
  const SubsetFit fit = select_terms(c, ratio);
  if (!fit.feasible) return out;
  out.fit_chi2_per_dof = ratio;
  const double inflate = std::max(1.0, ratio);  // never narrower than the points allow
  // The delta method, se(c) = se(c^2) / 2c, for the terms that passed the test on c^2.
  const auto term = [&](int j, std::optional<double>& value, std::optional<double>& se) {
    if (!(fit.theta[j] > 0)) return;
    const double v = std::sqrt(fit.theta[j]);
    value = v;
    se = std::sqrt(fit.cov(j, j) * inflate) / (2.0 * v);
  };
  term(0, out.quantization_arcsec, out.quantization_se);
  term(1, out.angle_random_walk_deg_rth, out.angle_random_walk_se);
  term(2, out.bias_instability_dph, out.bias_instability_se);
  term(3, out.rate_random_walk_dph_rth, out.rate_random_walk_se);
  if (out.bias_instability_dph) out.bias_instability_tau_s = flattest_tau(c, fit.theta);
  return out;
}

double noise_model_adev(const NoiseTerms& t, double tau_s) {
  const auto sq = [](const std::optional<double>& v) { return v ? *v * *v : 0.0; };
  return std::sqrt(model_var({sq(t.quantization_arcsec), sq(t.angle_random_walk_deg_rth),
                              sq(t.bias_instability_dph), sq(t.rate_random_walk_dph_rth)},
                             tau_s));
}

}  // namespace station::compensation
