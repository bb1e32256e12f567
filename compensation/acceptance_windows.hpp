// The mean of a counter's output over a measuring window and its standard error, for the
// acceptance steps (issue 36): a ladder's dwells, a set of positions. Pure maths.
//
// Error model (IEEE Std 952-1997 Annex C, the rate-noise terms of an RLG/FOG: angle random walk
// N, white in rate, and quantization noise Q, the counter's whole pulses). A window's mean rate
// is its pulse count over its span T: m = (N_end - N_start) / T, the per-sample quantization
// telescoping to the two ends. So
//     Var(m) = S / T + q(T)^2,
// S the white rate noise's density (unit^2 s: N^2 in the unit of the series), q(T) the two ends'
// rounding (mean_quantization_pps: two independent uniform errors of one pulse, GUM 4.3.7).
// q is known; S is the gyro's and is estimated.
//
// Estimating S (pooled batch means). Each window is cut into k consecutive batches of equal
// count, span D (Schmeiser, "Batch size effects in the analysis of simulation output", Oper. Res.
// 30(3):556, 1982). A batch mean has variance S / D + q(D)^2, and neighbouring batches share an
// end, so Cov(m_b, m_(b+1)) = -q(D)^2 / 2; then for ss = sum_b (m_b - mean of the m_b)^2,
// E[ss] = sum Var(m_b) - k Var(mean) = (k - 1) S / D + (k - 1/k) q(D)^2, and
// D ss - D (k - 1/k) q(D)^2 estimates (k - 1) S. A 1 Hz RLG series is mostly rounding over a
// few seconds (0.003 deg/sqrt(h) and 1.5" pulses: S / D = 0.0144 / D pulse^2/s^2 against
// q(D)^2 = 1 / (6 D^2)), so one window's estimate is noisy and, clipped at 0 on its own, biased
// upwards: the station-level Monte Carlo measured K within 1 SE in 0.796 of 240 ladders for a
// nominal 0.683 with per-window batch means. The white noise is the gyro's (IEEE 952 Annex C's
// N is one number per gyro), so S is pooled over all of a serial's measuring windows (ladders
// and positions: the pooled variance, each window's deviations about its own mean, dof =
// sum (k_w - 1)) and clipped at 0 once. Batches hold at least kMinPerBatch samples: shorter
// ones end at phases too close to be independent (at 5 s the pooled S came out 18 % low in a
// simulation of the counter, at 10 s and 15 s within 1 %). That simulation (6 ladder windows
// of 59 s, 4 of 300 s, 1200 draws) gave S's relative sd 0.26 and coverage 0.684 / 0.955 at 1 / 2
// SE; the station-level one is tests/station/test_acceptance_coverage.cpp.
// Not covered: noise correlated beyond a batch (bias instability, a drifting plateau) within a
// window, and a white noise that differs between windows (a gyro whose noise changes with rate).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

namespace station::compensation {

/// The sd of a mean count rate over `window_s` from the two ends' rounding, pulses/s: the count
/// is exact to the phase of the first and last pulse, two independent uniform errors of one
/// pulse, their difference sd 1/sqrt(6) pulse (GUM 4.3.7). 0 for a window_s <= 0. Times the
/// pulse weight (arcsec) it is deg/h (arcsec/s = deg/h).
double mean_quantization_pps(double window_s);

/// One window's series: values (a rate, any unit) at consecutive samples and each sample's
/// span, s (> 0), the same length.
struct WindowSeries {
  std::span<const double> values;
  std::span<const double> spans_s;
};

/// The white rate noise density S of a serial's windows (pooled batch means, above), in the
/// series' unit squared times s; `pulse_unit`: one pulse per second in the series' unit (1 for
/// pulses/s, the pulse weight for deg/h). A window shorter than 2 kMinPerBatch samples is cut
/// into 2 batches, one of fewer than 2 samples adds nothing; empty when none adds, 0 when the
/// pooled estimate is below 0.
std::optional<double> pooled_white_density(std::span<const WindowSeries> windows,
                                           double pulse_unit);

/// The least samples in a batch, and the most batches a window is cut into.
inline constexpr std::size_t kMinPerBatch = 10, kMaxBatches = 30;

/// A window's mean and its standard error sqrt(S / T + q(T)^2) (T the sum of the spans).
struct WindowMean {
  double mean = 0;
  double se = 0;
  double span_s = 0;
  std::size_t n = 0;
};

/// The window's mean with its error from `white_density` (pooled_white_density) and the
/// rounding of its two ends; empty for an empty window.
std::optional<WindowMean> window_mean(const WindowSeries& w, double white_density,
                                      double pulse_unit);

}  // namespace station::compensation
