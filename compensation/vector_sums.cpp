// The ADEV curve's long sums with vector arithmetic: squared differences of the angle for every
// tau (a tiled sweep for the near lags, chains for the far ones), and the lag-1 noise
// identification's sums of a tau-averaged series.
#include "compensation/vector_sums.hpp"

#include <algorithm>
#include <utility>

namespace station::compensation {
namespace {

// Doubles as one value (GCC's vector extension), the machine's native width in each kernel:
// 8 with AVX-512, 4 with AVX2, 2 with SSE2 (a wider type than the machine's is kept in memory by
// GCC: three times slower). The arithmetic is the same IEEE operations lane by lane.
using V2 = double __attribute__((vector_size(16)));
using V4 = double __attribute__((vector_size(32)));
using V8 = double __attribute__((vector_size(64)));
template <class V>
constexpr std::size_t kWidth = sizeof(V) / sizeof(double);

constexpr std::size_t kLanes = 32;        // partial sums of a difference sum (vector_sums.hpp)
constexpr std::size_t kSeriesLanes = 16;  // partial sums of a series' sum
// Terms per tile (a multiple of kLanes): 3 x 16 KiB per factor, every factor's share of the
// angle taken while the tile's neighbourhood is still in the core's cache.
constexpr std::size_t kTile = 2048;
// The chained factors (vector_sums.hpp): from 2^13 up, a level's stride M a multiple of the
// block, its factors up to 16 M. A window of 64 blocks of one chain plus the 48 blocks a factor of
// the level reaches beyond it (3 x 16, Hadamard) are 112 x 2 KiB, well inside the core's cache:
// every angle value comes from memory once a level, not once for every lag that reads it.
constexpr std::size_t kChainFrom = 8192;
constexpr std::size_t kChainBlock = 256;  // a multiple of kLanes: block k0 starts in lane 0
constexpr std::size_t kChainSpan = 16;
constexpr std::size_t kChainWindow = 64;

// The kernels are templates on the vector type, always inlined into one entry point per
// instruction set (target attribute), picked once by what the CPU has. The file is compiled with
// -ffp-contract=off (CMakeLists.txt): the AVX-512 kernel fuses no product into a sum (AVX-512F
// has FMA), and every machine gets the same bits.
#define STATION_INLINE inline __attribute__((always_inline))
#pragma GCC diagnostic ignored "-Wpsabi"  // vectors passed by value only inside inlined code

// The partial sums added pairwise: ((p0 + p1) + (p2 + p3)) + ...
STATION_INLINE double pairwise_total(double* p, std::size_t n) {
  for (; n > 1; n /= 2) {
    for (std::size_t i = 0; i < n / 2; ++i) p[i] = p[2 * i] + p[2 * i + 1];
  }
  return p[0];
}

template <class V>
STATION_INLINE V load(const double* p) {
  V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
template <class V>
STATION_INLINE void store(double* p, const V& v) {
  __builtin_memcpy(p, &v, sizeof v);
}

// Allan: (theta[k+2m] - 2 theta[k+m] + theta[k])^2 (SP 1065 eq. 11, x = tau0 theta).
struct Second {
  template <class V>
  STATION_INLINE static V diff(const double* t, std::size_t m) {
    return load<V>(t + 2 * m) - 2.0 * load<V>(t + m) + load<V>(t);
  }
};
// Hadamard: (theta[k+3m] - 3 theta[k+2m] + 3 theta[k+m] - theta[k])^2 (SP 1065 eq. 23).
struct Third {
  template <class V>
  STATION_INLINE static V diff(const double* t, std::size_t m) {
    return load<V>(t + 3 * m) - 3.0 * load<V>(t + 2 * m) + 3.0 * load<V>(t + m) - load<V>(t);
  }
};
// The same with one lane: the last terms of a sum.
template <class Diff>
STATION_INLINE double diff1(const double* t, std::size_t m) {
  using V1 = double __attribute__((vector_size(8)));
  return Diff::template diff<V1>(t, m)[0];
}

// Adds the terms k0 <= k < k1 (k0 a multiple of kLanes) at lag m to the kLanes partial sums.
template <class V, class Diff>
STATION_INLINE void add_terms(const double* theta, std::size_t m, std::size_t k0, std::size_t k1,
                              double* partial) {
  constexpr std::size_t w = kWidth<V>, nv = kLanes / w;
  V s[nv];
  for (std::size_t v = 0; v < nv; ++v) s[v] = load<V>(partial + w * v);
  std::size_t k = k0;
  for (; k + kLanes <= k1; k += kLanes) {
#pragma GCC unroll 16  // the partial sums in registers, not reloaded from the stack each step
    for (std::size_t v = 0; v < nv; ++v) {
      const V d = Diff::template diff<V>(theta + k + w * v, m);
      s[v] += d * d;
    }
  }
  for (std::size_t v = 0; v < nv; ++v) store(partial + w * v, s[v]);
  for (; k < k1; ++k) {  // the last terms of the sum, each into its own partial
    const double d = diff1<Diff>(theta + k, m);
    partial[k % kLanes] += d * d;
  }
}

// Adds the terms of one chain (vector_sums.hpp) at lag m: the blocks k = k_first + b stride +
// [0, kChainBlock) for b < blocks, each cut at `terms`, the partial sums kept in registers from
// block to block. A block cut short is the chain's last: its tail goes lane by lane.
template <class V, class Diff>
STATION_INLINE void add_chain_terms(const double* theta, std::size_t m, std::size_t k_first,
                                    std::size_t stride, std::size_t blocks, std::size_t terms,
                                    double* partial) {
  constexpr std::size_t w = kWidth<V>, nv = kLanes / w;
  V s[nv];
  for (std::size_t v = 0; v < nv; ++v) s[v] = load<V>(partial + w * v);
  std::size_t k = k_first, end = k_first;
  for (std::size_t b = 0; b < blocks && k < terms; ++b, k = k_first + b * stride) {
    end = std::min(k + kChainBlock, terms);
    for (; k + kLanes <= end; k += kLanes) {
#pragma GCC unroll 16
      for (std::size_t v = 0; v < nv; ++v) {
        const V d = Diff::template diff<V>(theta + k + w * v, m);
        s[v] += d * d;
      }
    }
    if (k < end) break;  // the chain's last block, cut short: its tail below
  }
  for (std::size_t v = 0; v < nv; ++v) store(partial + w * v, s[v]);
  for (; k < end; ++k) {
    const double d = diff1<Diff>(theta + k, m);
    partial[k % kLanes] += d * d;
  }
}

// 0, 1, ..., w - 1: a constant, so a ramp is one add (built lane by lane through memory it cost
// a store-forwarding stall per vector: half the noise identification's time, issue 37).
template <class V, std::size_t... I>
constexpr V iota(std::index_sequence<I...>) {
  return V{static_cast<double>(I)...};
}
template <class V>
constexpr V kIota = iota<V>(std::make_index_sequence<kWidth<V>>());
// t0, t0 + 1, ... as doubles (exact below 2^53).
template <class V>
STATION_INLINE V ramp(double t0) {
  return t0 + kIota<V>;
}
// x_t = y_t - (icpt + slope t) for the lanes' t from t0.
template <class V>
STATION_INLINE V residual(const double* y, double t0, double icpt, double slope) {
  return load<V>(y) - (icpt + slope * ramp<V>(t0));
}

// Sum y_t, sum t y_t into sums[0], sums[1]: kSeriesLanes partials each, the tail in its lanes.
template <class V>
STATION_INLINE void line_sums_into(const double* y, std::size_t n, double* sums) {
  constexpr std::size_t w = kWidth<V>, nv = kSeriesLanes / w;
  V sy[nv] = {}, sty[nv] = {};
  std::size_t k = 0;
  for (; k + kSeriesLanes <= n; k += kSeriesLanes) {
#pragma GCC unroll 16
    for (std::size_t v = 0; v < nv; ++v) {
      const V yv = load<V>(y + k + w * v);
      sy[v] += yv;
      sty[v] += ramp<V>(static_cast<double>(k + w * v)) * yv;
    }
  }
  double py[kSeriesLanes], pty[kSeriesLanes];
  for (std::size_t v = 0; v < nv; ++v) {
    store(py + w * v, sy[v]);
    store(pty + w * v, sty[v]);
  }
  for (; k < n; ++k) {
    py[k % kSeriesLanes] += y[k];
    pty[k % kSeriesLanes] += static_cast<double>(k) * y[k];
  }
  sums[0] = pairwise_total(py, kSeriesLanes);
  sums[1] = pairwise_total(pty, kSeriesLanes);
}

// The same line sums with the sequential sum of y into sums[2]: the chain's adds one at a time.
template <class V>
STATION_INLINE void sequential_line_sums_into(const double* y, std::size_t n, double* sums) {
  constexpr std::size_t w = kWidth<V>, nv = kSeriesLanes / w;
  V sy[nv] = {}, sty[nv] = {};
  double chain = 0;
  std::size_t k = 0;
  for (; k + kSeriesLanes <= n; k += kSeriesLanes) {
#pragma GCC unroll 16
    for (std::size_t v = 0; v < nv; ++v) {
      const V yv = load<V>(y + k + w * v);
      sy[v] += yv;
      sty[v] += ramp<V>(static_cast<double>(k + w * v)) * yv;
    }
#pragma GCC unroll 16
    for (std::size_t i = 0; i < kSeriesLanes; ++i) chain += y[k + i];
  }
  double py[kSeriesLanes], pty[kSeriesLanes];
  for (std::size_t v = 0; v < nv; ++v) {
    store(py + w * v, sy[v]);
    store(pty + w * v, sty[v]);
  }
  for (; k < n; ++k) {
    py[k % kSeriesLanes] += y[k];
    pty[k % kSeriesLanes] += static_cast<double>(k) * y[k];
    chain += y[k];
  }
  sums[0] = pairwise_total(py, kSeriesLanes);
  sums[1] = pairwise_total(pty, kSeriesLanes);
  sums[2] = chain;
}

// Sum x_t, sum x_t^2 (t < n) and sum x_t x_{t+1} (t < n - 1) into sums[0..2].
template <class V>
STATION_INLINE void lag_sums_into(const double* y, std::size_t n, double icpt, double slope,
                                  double* sums) {
  constexpr std::size_t w = kWidth<V>, nv = kSeriesLanes / w;
  V sx[nv] = {}, sxx[nv] = {}, sxn[nv] = {};
  std::size_t k = 0;
  for (; k + kSeriesLanes + 1 <= n; k += kSeriesLanes) {
#pragma GCC unroll 16
    for (std::size_t v = 0; v < nv; ++v) {
      const double t = static_cast<double>(k + w * v);
      const V x = residual<V>(y + k + w * v, t, icpt, slope);
      const V next = residual<V>(y + k + w * v + 1, t + 1, icpt, slope);
      sx[v] += x;
      sxx[v] += x * x;
      sxn[v] += x * next;
    }
  }
  double p[3][kSeriesLanes];
  for (std::size_t v = 0; v < nv; ++v) {
    store(p[0] + w * v, sx[v]);
    store(p[1] + w * v, sxx[v]);
    store(p[2] + w * v, sxn[v]);
  }
  const auto x_at = [&](std::size_t t) { return y[t] - (icpt + slope * static_cast<double>(t)); };
  for (; k < n; ++k) {
    const double x = x_at(k);
    p[0][k % kSeriesLanes] += x;
    p[1][k % kSeriesLanes] += x * x;
    if (k + 1 < n) p[2][k % kSeriesLanes] += x * x_at(k + 1);
  }
  for (std::size_t j = 0; j < 3; ++j) sums[j] = pairwise_total(p[j], kSeriesLanes);
}

// One entry point per instruction set for each kernel, and the one the CPU runs.
struct Kernels {
  void (*second)(const double*, std::size_t, std::size_t, std::size_t, double*);
  void (*third)(const double*, std::size_t, std::size_t, std::size_t, double*);
  void (*line)(const double*, std::size_t, double*);
  void (*sequential_line)(const double*, std::size_t, double*);
  void (*lag)(const double*, std::size_t, double, double, double*);
  void (*chain_second)(const double*, std::size_t, std::size_t, std::size_t, std::size_t,
                       std::size_t, double*);
  void (*chain_third)(const double*, std::size_t, std::size_t, std::size_t, std::size_t,
                      std::size_t, double*);
};

#define STATION_KERNELS(name, V, attr)                                                         \
  attr void name##_second(const double* t, std::size_t m, std::size_t a, std::size_t b,        \
                          double* p) {                                                         \
    add_terms<V, Second>(t, m, a, b, p);                                                       \
  }                                                                                            \
  attr void name##_third(const double* t, std::size_t m, std::size_t a, std::size_t b,         \
                         double* p) {                                                          \
    add_terms<V, Third>(t, m, a, b, p);                                                        \
  }                                                                                            \
  attr void name##_line(const double* y, std::size_t n, double* s) {                           \
    line_sums_into<V>(y, n, s);                                                                \
  }                                                                                            \
  attr void name##_sequential_line(const double* y, std::size_t n, double* s) {                \
    sequential_line_sums_into<V>(y, n, s);                                                     \
  }                                                                                            \
  attr void name##_lag(const double* y, std::size_t n, double i, double sl, double* s) {       \
    lag_sums_into<V>(y, n, i, sl, s);                                                          \
  }                                                                                            \
  attr void name##_chain_second(const double* t, std::size_t m, std::size_t k, std::size_t st, \
                                std::size_t nb, std::size_t te, double* p) {                   \
    add_chain_terms<V, Second>(t, m, k, st, nb, te, p);                                        \
  }                                                                                            \
  attr void name##_chain_third(const double* t, std::size_t m, std::size_t k, std::size_t st,  \
                               std::size_t nb, std::size_t te, double* p) {                    \
    add_chain_terms<V, Third>(t, m, k, st, nb, te, p);                                         \
  }                                                                                            \
  constexpr Kernels name{name##_second,          name##_third, name##_line,                    \
                         name##_sequential_line, name##_lag,   name##_chain_second,            \
                         name##_chain_third};

STATION_KERNELS(kBaseline, V2, )  // SSE2 on x86-64; what the compiler makes of it elsewhere
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
STATION_KERNELS(kAvx2, V4, __attribute__((target("avx2"))))
STATION_KERNELS(kAvx512, V8, __attribute__((target("avx512f"))))
#endif

const Kernels& kernels() {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  static const Kernels& chosen = []() -> const Kernels& {
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f")) return kAvx512;
    if (__builtin_cpu_supports("avx2")) return kAvx2;
    return kBaseline;
  }();
  return chosen;
#else
  return kBaseline;
#endif
}

}  // namespace

LineSums line_sums(std::span<const double> y) {
  double s[2];
  kernels().line(y.data(), y.size(), s);
  return {s[0], s[1]};
}

SequentialAndLineSums sequential_and_line_sums(std::span<const double> y) {
  double s[3];
  kernels().sequential_line(y.data(), y.size(), s);
  return {s[2], {s[0], s[1]}};
}

LagSums residual_lag_sums(std::span<const double> y, double icpt, double slope) {
  double s[3];
  kernels().lag(y.data(), y.size(), icpt, slope, s);
  return {s[0], s[1], s[2]};
}

std::vector<std::size_t> difference_sum_strides(std::span<const std::size_t> m_list) {
  std::vector<std::size_t> stride(m_list.size(), 0);
  for (std::size_t i = 0; i < m_list.size(); ++i) {
    const std::size_t m = m_list[i];
    if (stride[i] != 0 || m < kChainFrom || m % kChainBlock != 0) continue;
    for (std::size_t j = i; j < m_list.size() && m_list[j] <= kChainSpan * m; ++j) {
      if (stride[j] == 0 && m_list[j] % m == 0) stride[j] = m;
    }
  }
  return stride;
}

std::vector<double> difference_sums(std::span<const double> theta,
                                    std::span<const std::size_t> m_list, int order) {
  const Kernels& kernel = kernels();
  const auto add = order == 3 ? kernel.third : kernel.second;
  const auto add_chain = order == 3 ? kernel.chain_third : kernel.chain_second;
  const std::vector<std::size_t> stride = difference_sum_strides(m_list);
  std::vector<std::size_t> terms(m_list.size());
  std::size_t most = 0;  // the tiled sweep's longest sum
  for (std::size_t i = 0; i < m_list.size(); ++i) {
    terms[i] = theta.size() - static_cast<std::size_t>(order) * m_list[i];
    if (stride[i] == 0) most = std::max(most, terms[i]);
  }
  std::vector<double> partial(m_list.size() * kLanes, 0.0);
  for (std::size_t k0 = 0; k0 < most; k0 += kTile) {
    for (std::size_t i = 0; i < m_list.size(); ++i) {
      if (stride[i] != 0 || k0 >= terms[i]) continue;
      add(theta.data(), m_list[i], k0, std::min(k0 + kTile, terms[i]), &partial[i * kLanes]);
    }
  }
  // Each level's chains: for each block of residues c0 + [0, kChainBlock) modulo the stride, its
  // chain's blocks a window at a time, every factor of the level through the window in turn.
  for (std::size_t i = 0; i < m_list.size(); ++i) {
    const std::size_t level = stride[i];
    if (level == 0 || level != m_list[i]) continue;  // a level starts at its stride
    std::vector<std::size_t> members;                // its factors (a long `all` list: few)
    for (std::size_t j = i; j < m_list.size() && m_list[j] <= kChainSpan * level; ++j)
      if (stride[j] == level) members.push_back(j);
    const std::size_t blocks = theta.size() / level + 1;
    for (std::size_t c0 = 0; c0 < level; c0 += kChainBlock) {
      for (std::size_t b0 = 0; b0 < blocks; b0 += kChainWindow) {
        for (const std::size_t j : members) {
          add_chain(theta.data(), m_list[j], c0 + b0 * level, level, kChainWindow, terms[j],
                    &partial[j * kLanes]);
        }
      }
    }
  }
  std::vector<double> sums(m_list.size());
  for (std::size_t i = 0; i < m_list.size(); ++i)
    sums[i] = pairwise_total(&partial[i * kLanes], kLanes);
  return sums;
}

}  // namespace station::compensation
