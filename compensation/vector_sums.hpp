// The long sums of an ADEV curve, vectorised: the sums of squared differences of the integrated
// angle that the overlapping Allan and Hadamard variances are made of (NIST SP 1065, Riley 2008,
// §5.2.4 eq. 11 and §5.2.8 eq. 23, with phase x = tau0 theta), for all averaging factors of a
// curve, and the sums the lag-1 noise identification takes of each tau-averaged series
// (noise_id.hpp). Each sum is kept in 32 partial sums (16 for the series' sums; term k into
// partial k mod 32) added pairwise at the end, the terms of a partial taken in increasing k, or
// for a chained factor in its chain's order (difference_sums): the same bits on every machine,
// whichever vector width (AVX-512, AVX2 or SSE2, picked by what the CPU has) computes them.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace station::compensation {

/// For each factor m of `m_list` (increasing, order * m < theta.size()), the sum over
/// k < theta.size() - order * m of the squared order-th difference of theta at lag m:
/// (theta[k+2m] - 2 theta[k+m] + theta[k])^2 for order 2 (Allan),
/// (theta[k+3m] - 3 theta[k+2m] + 3 theta[k+m] - theta[k])^2 for order 3 (Hadamard).
/// Factors with no chain stride (difference_sum_strides: 0) take their terms in increasing k, the
/// angle swept once in tiles, every such factor's terms of a tile taken while the tile is in cache
/// (the streams at lags m and 2m share it up to the cache's size). A chained factor m of stride M
/// takes its terms k = c + b M (residue c < M, chain block b) by blocks of 256 residues in
/// increasing order, within a block by b, then c, increasing: the far lags' streams would each
/// bring the whole angle from memory (~14 of them at 10^7 samples, issue 37), while a level's
/// chains read each angle value once for all its factors, the blocks a factor reaches in cache.
/// Pure.
std::vector<double> difference_sums(std::span<const double> theta,
                                    std::span<const std::size_t> m_list, int order);

/// The chain stride of each factor of `m_list` (increasing), 0 for none: a level starts at the
/// first factor not yet in one that is at least 2^13 and a multiple of 256; its stride M is that
/// factor, and it takes every factor not yet in a level that is a multiple of M and at most 16 M.
/// Octave factors: 2^13 .. 2^17 in one level, 2^18 .. 2^22 in the next. Pure.
std::vector<std::size_t> difference_sum_strides(std::span<const std::size_t> m_list);

/// Sum y_t and sum t y_t over t = 0 .. n-1: what the least-squares line of y needs besides the
/// closed forms of sum t and sum t^2. Pure.
struct LineSums {
  double y = 0, ty = 0;
};
LineSums line_sums(std::span<const double> y);

/// line_sums of y and, in the same pass, the plain sum y_0 + y_1 + ... + y_{n-1} added one value
/// at a time in increasing t (the rounding of a sequential sum, which the angle's mean keeps; its
/// chain of adds hides the line sums' work and their read of y). Pure.
struct SequentialAndLineSums {
  double sequential = 0;
  LineSums line;
};
SequentialAndLineSums sequential_and_line_sums(std::span<const double> y);

/// With x_t = y_t - (icpt + slope t): sum x_t, sum x_t^2 (t < n) and sum x_t x_{t+1} (t < n-1),
/// the lag-1 autocorrelation's sums (Riley & Greenhall 2004, eq. 2). Pure.
struct LagSums {
  double x = 0, xx = 0, x_next = 0;
};
LagSums residual_lag_sums(std::span<const double> y, double icpt, double slope);

}  // namespace station::compensation
