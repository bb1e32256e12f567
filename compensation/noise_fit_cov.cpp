// The covariance of overlapping AVAR estimates under the IEEE 952 terms (noise_fit_cov.hpp has
// the formulas and their sources). Here: how the sum over lags j is evaluated cheaply (up to
// millions of lags per pair of points; ~15 us per pair, 3 ms for an octave curve of 2e6 samples,
// within 1e-3 of the plain sum: test NoiseFitCovariance.MatchesTheSumOverEveryLag).
//
// In sample units (tau0 = 1) C_mn(j) has kinks where an argument j + a m - b n vanishes, at the
// nine breakpoints j = b n - a m, and count(j) has kinks at 0 and M_m - M_n. Those are summed
// one by one. Between them C is a polynomial for white FM (|t|) and random-walk FM (|t|^3), so
// count(j) C(j)^2 is one of degree <= 7, which 8-point Gauss-Legendre integrates exactly; the sum
// over the integer lags of a piece is that integral over [first - 1/2, last + 1/2] (midpoint
// rule: error f''/24 per lag, a relative ~1 / (8 min(m, n)^2) next to a kink, so within
// kDirectEdge of a kink the lags are summed one by one while min(m, n) < kDirectBelow). White
// PM lives on the breakpoints only (G(0) = Q^2). White and random-walk FM vanish outside the
// overlap -2m < j < 2n (a double second difference of a cubic is 0); flicker FM decays as 1/j^2
// and is carried to the ends of the data: on panels growing by kPanelGrowth away from the
// kinks, and beyond (m + n) kFarFactor from its expansion (far_flicker), not truncated.
#include "compensation/noise_fit_cov.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace station::compensation {
namespace {

constexpr std::array<double, 3> kDiff = {1.0, -2.0, 1.0};  // x_{k+2m} - 2 x_{k+m} + x_k
// Gauss-Legendre, 8 points on [-1, 1], +-x with weight w (Abramowitz & Stegun, Table 25.4).
constexpr std::array<double, 4> kGlX = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                        0.9602898564975363};
constexpr std::array<double, 4> kGlW = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                        0.1012285362903763};
constexpr double kDirectEdge = 8;    // lags summed one by one next to a kink
constexpr double kDirectBelow = 32;  // ... when min(m, n) is below this
constexpr double kFarFactor = 8;     // flicker: the expansion beyond (m + n) * this
constexpr double kPanelGrowth = 8;   // flicker: panel length / distance from the kinks

// sums[t][u] = sum_j count(j) C_t(j) C_u(j) for t <= u, t and u indexing theta (Q, N, B, K).
using Sums = std::array<std::array<double, 4>, 4>;
using Cov4 = std::array<double, 4>;  // C_t(j) for Q, N, B, K in sample units

// One pair of estimates: averaging factors m, n and their numbers of terms M_m, M_n.
struct Pair {
  double m, n, mm, mn;
  double lo() const { return -(mn - 1); }  // lags j = k - l of the index pairs
  double hi() const { return mm - 1; }
  // Number of pairs (k, l), 0 <= k < M_m, 0 <= l < M_n, with k - l = j (continuous in j).
  double count(double j) const { return std::max(0.0, std::min(mm, mn + j) - std::max(0.0, j)); }
  Pair swapped() const { return {n, m, mn, mm}; }  // C_nm(j) = C_mn(-j), count likewise
};

// C_t(x) for white FM (G = |t|), flicker FM (t^2 ln|t|) and random-walk FM (|t|^3) in sample
// units; the t^2 ln(tau0) part of flicker is annihilated by the second difference. Q stays 0.
Cov4 diff_cov(const Pair& p, double x) {
  Cov4 c{};
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      const double t = x + a * p.m - b * p.n;
      const double w = kDiff[a] * kDiff[b];
      const double at = std::fabs(t);
      c[1] += w * at;
      c[2] += at > 0 ? w * t * t * std::log(at) : 0.0;
      c[3] += w * at * at * at;
    }
  }
  return c;
}

// Flicker's C far from the overlap (|u| >> m + n, u = x + m - n the centre of the nine
// arguments): the second central difference of step h is h^2 D^2 + h^4 D^4 / 12 + O(h^6)
// (Taylor), and for t^2 ln|t| D^4 = -2 / t^2, D^6 = -12 / t^4; the next term is O((m+n)/u)^4
// relative. Evaluated without the cancellation of nine large terms.
Cov4 far_flicker(const Pair& p, double x) {
  const double u2 = (x + p.m - p.n) * (x + p.m - p.n);
  const double mn2 = p.m * p.m * p.n * p.n;
  return {0.0, 0.0, -2 * mn2 / u2 - mn2 * (p.m * p.m + p.n * p.n) / (u2 * u2), 0.0};
}

void add(Sums& s, double w, const Cov4& c) {
  for (int t = 0; t < 4; ++t)
    for (int u = t; u < 4; ++u) s[t][u] += w * c[t] * c[u];
}

template <class CovFn>
void sum_direct(const Pair& p, double first, double last, CovFn cov, Sums& s) {
  for (double j = first; j <= last; ++j) add(s, p.count(j), cov(j));
}

// Integral of count(x) C(x) C(x)' over [lo, hi] split at `edges`, 8-point Gauss-Legendre each.
template <class CovFn>
void integrate(const Pair& p, double lo, double hi, std::vector<double> edges, CovFn cov, Sums& s) {
  edges.insert(edges.end(), {hi, 0.0, p.mm - p.mn});  // count's kinks too
  std::sort(edges.begin(), edges.end());
  double left = lo;
  for (const double e : edges) {
    if (e <= left || e > hi) continue;
    const double half = (e - left) / 2, mid = (e + left) / 2;
    for (std::size_t i = 0; i < kGlX.size(); ++i) {
      for (const double sign : {-1.0, 1.0}) {
        const double x = mid + sign * half * kGlX[i];
        add(s, half * kGlW[i] * p.count(x), cov(x));
      }
    }
    left = e;
  }
}

// The lags first..last strictly between two kinks: lag by lag within kDirectEdge of either
// end, the rest integrated on panels that start at min(m, n) from either end and grow by
// kPanelGrowth (flicker's C falls off as 1 / distance^2 beyond a cluster of kinks min(m, n)
// apart; its t^2 ln|t| at a kink costs 8-point Gauss-Legendre ~8^-6; polynomial terms are exact).
template <class CovFn>
void piece_sums(const Pair& p, double first, double last, CovFn cov, Sums& s) {
  // Lag by lag only where the midpoint rule is off by more than ~1e-4 (1 / (8 min(m, n)^2)).
  const double direct = std::min(p.m, p.n) < kDirectBelow ? kDirectEdge : 0.0;
  if (last - first + 1 <= 2 * direct) {
    sum_direct(p, first, last, cov, s);
    return;
  }
  sum_direct(p, first, first + direct - 1, cov, s);
  sum_direct(p, last - direct + 1, last, cov, s);
  const double lo = first + direct - 0.5, hi = last - direct + 0.5;
  std::vector<double> edges;
  for (double d = std::min(p.m, p.n); lo + d < hi - d; d *= kPanelGrowth) {
    edges.push_back(lo + d);
    edges.push_back(hi - d);
  }
  integrate(p, lo, hi, edges, cov, s);
}

// Lags -2m..2n, where the windows overlap: the kinks one by one, the pieces between them.
void overlap_sums(const Pair& p, Sums& s) {
  const double first = std::max(-2 * p.m, p.lo()), last = std::min(2 * p.n, p.hi());
  std::vector<double> knots = {first, last, 0.0, p.mm - p.mn};  // count's kinks
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) knots.push_back(b * p.n - a * p.m);
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
  std::erase_if(knots, [&](double k) { return k < first || k > last; });
  const auto exact = [&](double x) { return diff_cov(p, x); };
  for (std::size_t i = 0; i < knots.size(); ++i) {
    add(s, p.count(knots[i]), exact(knots[i]));
    if (i + 1 < knots.size() && knots[i + 1] - knots[i] > 1)
      piece_sums(p, knots[i] + 1, knots[i + 1] - 1, exact, s);
  }
}

// Lags j > 2n, right of the overlap, where only flicker FM is left: exact C out to
// 2n + (m + n) kFarFactor, its expansion beyond.
void flicker_tail(const Pair& p, Sums& s) {
  const auto exact = [&](double x) { return Cov4{0.0, 0.0, diff_cov(p, x)[2], 0.0}; };
  const auto expansion = [&](double x) { return far_flicker(p, x); };
  const double far = 2 * p.n + (p.m + p.n) * kFarFactor;
  if (p.hi() > 2 * p.n) piece_sums(p, 2 * p.n + 1, std::min(far, p.hi()), exact, s);
  if (p.hi() > far) {
    const double lo = far + 0.5, hi = p.hi() + 0.5, r = p.n - p.m;  // r: where u = 0
    std::vector<double> edges;
    for (double d = (lo - r) * kPanelGrowth; r + d < hi; d *= kPanelGrowth) edges.push_back(r + d);
    integrate(p, lo, hi, edges, expansion, s);
  }
}

// White PM: C_Q(j) = sum of c_a c_b over the (a, b) with j + a m - b n = 0, so only the
// breakpoints carry it.
void white_pm(const Pair& p, Sums& s) {
  std::vector<std::pair<double, double>> points;  // (lag, C_Q)
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      const double j = b * p.n - a * p.m;
      const auto it =
          std::find_if(points.begin(), points.end(), [j](const auto& q) { return q.first == j; });
      if (it == points.end())
        points.emplace_back(j, kDiff[a] * kDiff[b]);
      else
        it->second += kDiff[a] * kDiff[b];
    }
  }
  for (const auto& [j, cq] : points) {
    if (j < p.lo() || j > p.hi() || cq == 0) continue;
    Cov4 c = diff_cov(p, j);
    const double w = p.count(j) * cq;
    s[0][0] += w * cq;
    for (int u = 1; u < 4; ++u) s[0][u] += w * c[u];
  }
}

Sums lag_sums(const Pair& p) {
  Sums s{};
  overlap_sums(p, s);
  flicker_tail(p, s);
  Sums left{};
  flicker_tail(p.swapped(), left);  // lags j < -2m, mirrored
  s[2][2] += left[2][2];
  white_pm(p, s);
  return s;
}

}  // namespace

std::optional<AvarCovariance> AvarCovariance::of(std::span<const AdevPoint> pts) {
  if (pts.empty() || pts[0].m == 0) return std::nullopt;
  const double tau0 = pts[0].tau_s / static_cast<double>(pts[0].m);
  for (const auto& p : pts) {
    const bool same_tau0 =
        p.m > 0 && std::fabs(p.tau_s / static_cast<double>(p.m) - tau0) <= 1e-9 * tau0;
    if (!same_tau0 || p.n == 0 || !(tau0 > 0)) return std::nullopt;
  }
  // G in physical units = scale * G in sample units (noise_fit_cov.hpp): white PM Q^2,
  // white FM -0.5 * 3600 N^2 tau0 |j|, flicker B^2 tau0^2 / (2 pi) j^2 ln|j|, RW FM
  // K^2 tau0^3 |j|^3 / 43200.
  const Cov4 scale = {1.0, -1800.0 * tau0, tau0 * tau0 / (2 * std::numbers::pi),
                      tau0 * tau0 * tau0 / 43200.0};
  const auto k = static_cast<Eigen::Index>(pts.size());
  AvarCovariance out;
  for (int t = 0; t < 4; ++t)
    for (int u = t; u < 4; ++u) out.parts_[t][u] = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index i = 0; i < k; ++i) {
    for (Eigen::Index j = i; j < k; ++j) {
      const AdevPoint& a = pts[static_cast<std::size_t>(i)];
      const AdevPoint& b = pts[static_cast<std::size_t>(j)];
      const auto d = [](std::size_t v) { return static_cast<double>(v); };
      const Sums s = lag_sums({d(a.m), d(b.m), d(a.n), d(b.n)});
      const double pref = 2.0 / (4 * a.tau_s * a.tau_s * b.tau_s * b.tau_s * d(a.n) * d(b.n));
      for (int t = 0; t < 4; ++t) {
        for (int u = t; u < 4; ++u) {
          const double v = pref * scale[t] * scale[u] * s[t][u] * (t == u ? 1.0 : 2.0);
          out.parts_[t][u](i, j) = v;
          out.parts_[t][u](j, i) = v;
        }
      }
    }
  }
  return out;
}

Eigen::MatrixXd AvarCovariance::at(const NoiseTheta& theta) const {
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(parts_[0][0].rows(), parts_[0][0].cols());
  for (int t = 0; t < 4; ++t)
    for (int u = t; u < 4; ++u) c += theta[t] * theta[u] * parts_[t][u];
  return c;
}

}  // namespace station::compensation
