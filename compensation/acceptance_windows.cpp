// A window's mean count rate and its error (definitions and sources in acceptance_windows.hpp).
#include "compensation/acceptance_windows.hpp"

#include <algorithm>
#include <cmath>

namespace station::compensation {

double mean_quantization_pps(double window_s) {
  return window_s > 0 ? 1.0 / (window_s * std::sqrt(6.0)) : 0.0;
}

namespace {

/// One window's share of the pooled estimate: D ss - D q(D)^2 (k - 1/k) (acceptance_windows.hpp)
/// and its degrees of freedom k - 1.
struct BatchShare {
  double s_times_dof = 0;
  std::size_t dof = 0;
};

BatchShare batch_share(const WindowSeries& w, double pulse_unit) {
  const std::size_t n = std::min(w.values.size(), w.spans_s.size());
  // At least two batches when there are two samples: a short window still adds its share.
  const std::size_t k =
      std::min(kMaxBatches, std::max(n / kMinPerBatch, std::min<std::size_t>(n, 2)));
  if (k < 2) return {};
  const std::size_t per = n / k;
  std::vector<double> means, spans;
  for (std::size_t b = 0; b < k; ++b) {
    double sum = 0, span = 0;
    for (std::size_t i = b * per; i < (b + 1) * per; ++i) sum += w.values[i], span += w.spans_s[i];
    means.push_back(sum / static_cast<double>(per));
    spans.push_back(span);
  }
  double m = 0, d = 0;
  for (std::size_t b = 0; b < k; ++b) m += means[b], d += spans[b];
  m /= static_cast<double>(k);
  d /= static_cast<double>(k);  // the batches' span D (equal counts: equal spans at 1 Hz)
  double ss = 0;
  for (double x : means) ss += (x - m) * (x - m);
  const double q = pulse_unit * mean_quantization_pps(d);
  // E[ss] = (k - 1) S / D + (k - 1/k) q(D)^2 (acceptance_windows.hpp).
  const double kd = static_cast<double>(k);
  return {d * ss - (kd - 1.0 / kd) * d * q * q, k - 1};
}

}  // namespace

std::optional<double> pooled_white_density(std::span<const WindowSeries> windows,
                                           double pulse_unit) {
  double sum = 0;
  std::size_t dof = 0;
  for (const auto& w : windows) {
    const BatchShare s = batch_share(w, pulse_unit);
    sum += s.s_times_dof;
    dof += s.dof;
  }
  if (dof == 0) return std::nullopt;
  return std::max(sum / static_cast<double>(dof), 0.0);
}

std::optional<WindowMean> window_mean(const WindowSeries& w, double white_density,
                                      double pulse_unit) {
  const std::size_t n = std::min(w.values.size(), w.spans_s.size());
  if (n == 0) return std::nullopt;
  WindowMean m;
  m.n = n;
  // The count over the span: each sample's rate times its span (telescoping, above).
  for (std::size_t i = 0; i < n; ++i)
    m.mean += w.values[i] * w.spans_s[i], m.span_s += w.spans_s[i];
  if (!(m.span_s > 0)) return std::nullopt;
  m.mean /= m.span_s;
  const double q = pulse_unit * mean_quantization_pps(m.span_s);
  m.se = std::sqrt(std::max(white_density, 0.0) / m.span_s + q * q);
  return m;
}

}  // namespace station::compensation
