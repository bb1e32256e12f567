// The restricted likelihood by a Kalman filter, kLanes error models per pass (see the header).
//
// Harvey, "Forecasting, structural time series models and the Kalman filter" (1989): one filter
// (Gauss-Markov state g, random-walk state r; observed g + r + white) runs on y and on every
// column of X with the same gains (sec. 3.4.2, "augmented" filter); the innovations v and their
// variances f give the GLS normal equations [y X]' F^-1 [y X]; with b and s^2 concentrated out
// the restricted likelihood is (sec. 3.4 and 5.2; Harville 1977, JASA 72:320)
//   -2 l_R = sum log f + log |X' F^-1 X| + (n - p) log s^2,  s^2 = RSS_GLS / (n - p).
// The walk starts at 0 in each run (its level there is the constant's, and runs are independent).
#include "compensation/reml_filter.hpp"

// No product fused into a sum anywhere in this file: the AVX-512 copy of the pass (whose
// instruction set has FMA) then does the same IEEE operations on each lane as the SSE2 and AVX2
// copies, so a model's likelihood is the same bits whichever pass the CPU runs.
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace station::compensation::reml {
namespace {

/// The AVX-512 pass's lanes: eight models, one 512-bit register a step.
constexpr int kWideLanes = 8;
using SmallMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxColumns, kMaxColumns>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxColumns, 1>;

/// What a pass gathers per lane: [y X]' F^-1 [y X] (upper triangle) and sum log f.
template <int L>
struct Gathered {
  std::array<SmallMatrix, L> m;
  std::array<double, L> sum_log_f{};
};

// Inlined into each instruction set's copy of the pass (pass_on below), so it is compiled there.
#define STATION_INLINE inline __attribute__((always_inline))

/// The lanes' covariance of the two states (units of s^2) and their gains at one bin.
template <int L>
struct Riccati {
  double pgg[L], pgr[L], prr[L], f[L], inv_f[L], kg[L], kr[L];

  /// Time update over dt hours (Harvey sec. 3.2.1): the Gauss-Markov part decays by phi towards
  /// its stationary variance q, the walk's variance grows by w dt.
  STATION_INLINE void predict(const double* q, const double* w, const double* ph, double dt) {
    for (int l = 0; l < L; ++l) {
      pgg[l] = ph[l] * ph[l] * pgg[l] + q[l] * (1.0 - ph[l] * ph[l]);
      pgr[l] = ph[l] * pgr[l];
      prr[l] = prr[l] + w[l] * dt;
    }
  }
  /// The innovation variance f (states plus white, 1 - q) and the two gains.
  STATION_INLINE void gains(const double* q) {
    for (int l = 0; l < L; ++l) {
      f[l] = pgg[l] + 2 * pgr[l] + prr[l] + (1.0 - q[l]);
      inv_f[l] = 1.0 / f[l];
      kg[l] = (pgg[l] + pgr[l]) * inv_f[l];
      kr[l] = (pgr[l] + prr[l]) * inv_f[l];
    }
  }
  /// P <- P - K f K' (the Joseph form is not needed: f >= 1 - q keeps it well conditioned).
  STATION_INLINE void update() {
    for (int l = 0; l < L; ++l) {
      pgg[l] -= kg[l] * kg[l] * f[l];
      pgr[l] -= kg[l] * kr[l] * f[l];
      prr[l] -= kr[l] * kr[l] * f[l];
    }
  }
};

/// One pass over the bins for L models at once, K columns fixed at compile time. Every loop's
/// innermost index is the lane, so the compiler vectorizes across models.
template <int K, int L>
STATION_INLINE Gathered<L> pass(const double* z, Eigen::Index stride, Eigen::Index n,
                                const std::vector<double>& dt_h, const std::array<Model, L>& md) {
  double m[K * K][L] = {}, g[K][L] = {}, r[K][L] = {}, v[K][L];
  double q[L], w[L], ph[L], sum_log_f[L] = {}, prod_f[L];
  Riccati<L> p{};
  for (int l = 0; l < L; ++l) q[l] = md[l].q, w[l] = md[l].w_per_h, prod_f[l] = 1;
  for (Eigen::Index i = 0; i < n; ++i, z += stride) {
    const auto iu = static_cast<std::size_t>(i);
    const double dt = dt_h[iu];
    for (int l = 0; l < L; ++l) ph[l] = (*md[l].phi)[iu];
    if (dt < 0) {  // a run starts: the walk at 0, the Gauss-Markov part stationary
      for (int l = 0; l < L; ++l) p.pgg[l] = q[l], p.pgr[l] = p.prr[l] = 0;
      for (int c = 0; c < K; ++c)
        for (int l = 0; l < L; ++l) g[c][l] = r[c][l] = 0;
    } else {
      p.predict(q, w, ph, dt);
      for (int c = 0; c < K; ++c)
        for (int l = 0; l < L; ++l) g[c][l] *= ph[l];
    }
    p.gains(q);
    for (int c = 0; c < K; ++c)
      for (int l = 0; l < L; ++l) {
        v[c][l] = z[c] - g[c][l] - r[c][l];
        g[c][l] += p.kg[l] * v[c][l];
        r[c][l] += p.kr[l] * v[c][l];
      }
    p.update();
    for (int l = 0; l < L; ++l) prod_f[l] *= p.f[l];
    // f >= 1 - q >= 0.01, so the product of 64 bins' f stays far from underflow: one log per 64
    // bins instead of one per bin (the log was most of the cost).
    if ((i & 63) == 63)
      for (int l = 0; l < L; ++l) sum_log_f[l] += std::log(prod_f[l]), prod_f[l] = 1;
    for (int a = 0; a < K; ++a) {
      double va[L];
      for (int l = 0; l < L; ++l) va[l] = v[a][l] * p.inv_f[l];
      for (int b = a; b < K; ++b)
        for (int l = 0; l < L; ++l) m[a * K + b][l] += va[l] * v[b][l];
    }
  }
  Gathered<L> out;
  for (int l = 0; l < L; ++l) {
    out.sum_log_f[l] = sum_log_f[l] + std::log(prod_f[l]);
    out.m[l].resize(K, K);
    for (int a = 0; a < K; ++a)
      for (int b = 0; b < K; ++b) out.m[l](a, b) = m[a * K + b][l];
  }
  return out;
}

/// The pass for k columns, the copy compiled for the instruction set the caller was compiled for.
template <int L, int... Ks>
STATION_INLINE Gathered<L> pass_for(int k, const double* z, Eigen::Index stride, Eigen::Index n,
                                    const std::vector<double>& dt_h, const std::array<Model, L>& md,
                                    std::integer_sequence<int, Ks...>) {
  Gathered<L> out;
  ((k == Ks + 2 ? (out = pass<Ks + 2, L>(z, stride, n, dt_h, md), true) : false) || ...);
  return out;
}

using Columns2To10 = std::make_integer_sequence<int, kMaxColumns - 1>;

// The same pass for SSE2 (every x86-64), for AVX2, whose 256-bit registers hold all kLanes = 4
// lanes of a step (twice the work per instruction), and for AVX-512, eight lanes a 512-bit
// register (issue 37: the error model's passes were most of a fit). Each copy does the same IEEE
// operations on each lane in the same order (no FMA: contraction is off in this file), so the
// likelihoods are the same bits whichever runs.
Gathered<kLanes> pass_default(int k, const double* z, Eigen::Index stride, Eigen::Index n,
                              const std::vector<double>& dt_h,
                              const std::array<Model, kLanes>& md) {
  return pass_for<kLanes>(k, z, stride, n, dt_h, md, Columns2To10{});
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2"))) Gathered<kLanes> pass_avx2(int k, const double* z,
                                                           Eigen::Index stride, Eigen::Index n,
                                                           const std::vector<double>& dt_h,
                                                           const std::array<Model, kLanes>& md) {
  return pass_for<kLanes>(k, z, stride, n, dt_h, md, Columns2To10{});
}
__attribute__((target("avx512f"))) Gathered<kWideLanes> pass_avx512(
    int k, const double* z, Eigen::Index stride, Eigen::Index n, const std::vector<double>& dt_h,
    const std::array<Model, kWideLanes>& md) {
  return pass_for<kWideLanes>(k, z, stride, n, dt_h, md, Columns2To10{});
}
#endif

/// The widest pass the CPU has (asked once).
enum class Width { sse2, avx2, avx512 };
Width cpu_width() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const Width width = __builtin_cpu_supports("avx512f") ? Width::avx512
                             : __builtin_cpu_supports("avx2")  ? Width::avx2
                                                               : Width::sse2;
  return width;
#else
  return Width::sse2;
#endif
}

/// One pass of kLanes models over the first k columns of z's rows (`stride` apart).
Gathered<kLanes> pass_narrow(int k, const double* z, Eigen::Index stride, Eigen::Index n,
                             const std::vector<double>& dt_h, const std::array<Model, kLanes>& md) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (cpu_width() != Width::sse2) return pass_avx2(k, z, stride, n, dt_h, md);
#endif
  return pass_default(k, z, stride, n, dt_h, md);
}

/// The likelihoods from what one lane gathered over y and columns 1..p (the base) of z: the
/// restricted one, and with `ml` the maximum likelihood of the base and of the base with each
/// later gathered column.
Profile finish(const SmallMatrix& g, Eigen::Index p, double sum_log_f, Eigen::Index n,
               Deviances* ml) {
  const SmallMatrix mxx = g.block(1, 1, p, p).selfadjointView<Eigen::Upper>();
  const SmallVector mxy = g.row(0).segment(1, p).transpose();
  const Eigen::LDLT<SmallMatrix> ldlt(mxx);
  const SmallVector beta = ldlt.solve(mxy);
  const double rss = g(0, 0) - mxy.dot(beta);
  Profile out;
  const auto dof = static_cast<double>(n - p);
  if (ml != nullptr) ml->fill(std::numeric_limits<double>::infinity());
  if (!(rss > 0) || ldlt.info() != Eigen::Success) return out;
  out.sigma2 = rss / dof;
  out.minus2_loglik = sum_log_f + ldlt.vectorD().array().log().sum() + dof * std::log(out.sigma2);
  if (ml == nullptr) return out;
  const auto nd = static_cast<double>(n);
  (*ml)[0] = sum_log_f + nd * std::log(rss / nd);
  for (Eigen::Index c = p + 1; c < g.rows(); ++c) {
    // Adding column c: RSS falls by e^2 / d, e = g_cy - g_cx b, d = g_cc - g_cx M^-1 g_xc, the
    // Schur complement of the base's M = X' F^-1 X (e.g. Seber & Lee, Linear Regression
    // Analysis, 2nd ed., 2003, sec. 3.7). A column the base spans (zeros) has d = 0: no fall.
    const SmallVector mxc = g.col(c).segment(1, p);
    const double d = g(c, c) - mxc.dot(ldlt.solve(mxc)), e = g(0, c) - mxc.dot(beta);
    const double rss_c = d > 0 ? rss - e * e / d : rss;
    if (rss_c > 0) (*ml)[static_cast<std::size_t>(c - p)] = sum_log_f + nd * std::log(rss_c / nd);
  }
  return out;
}

}  // namespace

namespace {

/// Every model's pass over z's first `cols` columns, L at a time by `run`; `take(model index,
/// gathered, lane)` for each.
template <int L, typename Run, typename Take>
void passes_of(const RowMajor& z, Eigen::Index cols, const std::vector<double>& dt_h,
               std::span<const Model> models, Run run, Take take) {
  for (std::size_t first = 0; first < models.size(); first += L) {
    const std::size_t lanes = std::min<std::size_t>(L, models.size() - first);
    std::array<Model, L> md;
    for (std::size_t l = 0; l < L; ++l) md[l] = models[first + std::min(l, lanes - 1)];
    const Gathered<L> g = run(static_cast<int>(cols), z.data(), z.cols(), z.rows(), dt_h, md);
    for (std::size_t l = 0; l < lanes; ++l) take(first + l, g, l);
  }
}

/// The same, eight models a pass where the CPU has AVX-512 and more than four models are asked
/// (fewer would leave lanes idle), else four.
template <typename Take>
void each_pass(const RowMajor& z, Eigen::Index cols, const std::vector<double>& dt_h,
               std::span<const Model> models, Take take) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (cpu_width() == Width::avx512 && models.size() > static_cast<std::size_t>(kLanes))
    return passes_of<kWideLanes>(z, cols, dt_h, models, pass_avx512, take);
#endif
  passes_of<kLanes>(z, cols, dt_h, models, pass_narrow, take);
}

}  // namespace

void profiles(const RowMajor& z, const std::vector<double>& dt_h, std::span<const Model> models,
              std::span<Profile> out) {
  evaluate(z, z.cols() - 1, dt_h, models, out);
}

void evaluate(const RowMajor& z, Eigen::Index base, const std::vector<double>& dt_h,
              std::span<const Model> models, std::span<Profile> out, std::span<Deviances> ml) {
  const Eigen::Index cols = ml.empty() ? base + 1 : z.cols();
  each_pass(z, cols, dt_h, models, [&](std::size_t i, const auto& g, std::size_t l) {
    out[i] = finish(g.m[l], base, g.sum_log_f[l], z.rows(), ml.empty() ? nullptr : &ml[i]);
  });
}

}  // namespace station::compensation::reml
