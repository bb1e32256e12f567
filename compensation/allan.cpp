// Overlapping Allan deviation from the integrated angle, its confidence intervals, noise terms.
#include "compensation/allan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <tuple>

#include "compensation/chi_squared.hpp"
#include "compensation/limits.hpp"
#include "compensation/noise_edf.hpp"
#include "compensation/noise_id.hpp"
#include "compensation/vector_sums.hpp"

namespace station::compensation {
namespace {

void check_adev_arguments(double rate_hz, double confidence) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz) || !(confidence > 0.0 && confidence < 1.0)) {
    throw DataError("overlapping_adev: need rate_hz > 0 and 0 < confidence < 1, got " +
                    std::to_string(rate_hz) + ", " + std::to_string(confidence));
  }
}

// The mean rate in one sequential sum: the order whose rounding the angle has always had (the
// curve's values depend on the angle's last bits at small tau). With `check`, each sample is
// checked finite.
double rate_mean(std::span<const double> rate, bool check) {
  double sum = 0;
  for (std::size_t i = 0; i < rate.size(); ++i) {
    if (check && !std::isfinite(rate[i]))
      throw DataError("overlapping_adev: sample " + std::to_string(i) + ": " +
                      finite_problem(rate[i]));
    sum += rate[i];
  }
  return sum / static_cast<double>(rate.size());
}

// The same sequential sum, the rate's line sums for the lag-1 identification at m = 1 taken in
// its shadow (vector_sums.hpp): one pass over the rate for both. A sample that is not finite
// makes the sum not finite; only then are the samples checked one by one, to name it.
double rate_mean_and_line_sums(std::span<const double> rate, LineSums& line) {
  const SequentialAndLineSums sums = sequential_and_line_sums(rate);
  line = sums.line;
  if (!std::isfinite(sums.sequential)) return rate_mean(rate, true);
  return sums.sequential / static_cast<double>(rate.size());
}

// theta_0 = 0, theta_{k+1} = theta_k + (y_k - mean) into out[0 .. n]: a chain of adds, the running
// value kept in a register (not read back from memory; push_back instead was twice as slow).
void fill_angle(std::span<const double> rate, double mean, double* out) {
  double t = 0.0;
  out[0] = t;
  for (std::size_t i = 0; i < rate.size(); ++i) {
    t += rate[i] - mean;
    out[i + 1] = t;
  }
}

// fill_angle, and into pairs[b] the mean of samples 2b and 2b + 1 (BlockAverages at factor 2, the
// same operations) in the shadow of the angle's chain of adds: one pass over the rate for both.
void fill_angle_and_pairs(std::span<const double> rate, double mean, double* out, double* pairs) {
  double t = 0.0;
  out[0] = t;
  std::size_t i = 0;
  for (; i + 2 <= rate.size(); i += 2) {
    const double y0 = rate[i], y1 = rate[i + 1];
    t += y0 - mean;
    out[i + 1] = t;
    t += y1 - mean;
    out[i + 2] = t;
    pairs[i / 2] = (y0 + y1) / 2.0;
  }
  if (i < rate.size()) out[i + 1] = t + (rate[i] - mean);
}

// The working memory of a curve, kept by the thread for its next one: the angle (N + 1 values)
// and the tau-averaged series (N / 2). First touching fresh pages cost more than the curve: on the
// project's VM a 10^7-sample curve spent ~420 of its ~520 ms faulting in 120 MB that blocks above
// the heap's 32 MiB keep limit (station/common/allocator.hpp) bring fresh on every call, ~100 ms
// computing (docs/BENCHMARKS.md). 12 bytes a sample of the longest series the thread has taken.
std::span<double> curve_scratch(std::size_t n_values) {
  thread_local std::unique_ptr<double[]> memory;
  thread_local std::size_t size = 0;
  if (n_values > size) {
    memory.reset();  // the smaller block given back before the larger one is taken
    memory = std::make_unique_for_overwrite<double[]>(n_values);
    size = n_values;
  }
  return {memory.get(), n_values};
}

// One point of the curve, its interval still to come, from the sum of its squared differences
// (difference_sums.hpp). NIST SP 1065 §5.2.4, overlapping AVAR from phase data:
// AVAR(m tau0) = 1 / (2 tau^2 (N - 2m)) sum_k (x_{k+2m} - 2 x_{k+m} + x_k)^2, and §5.2.8,
// overlapping HVAR: 1 / (6 tau^2 (N - 3m)) sum_k (third difference)^2, with x = tau0 * theta and
// tau = m tau0, so tau0^2 cancels.
AdevPoint deviation_point(double sum, std::size_t n_theta, std::size_t m, double tau0_s,
                          int order) {
  const std::size_t n_terms = n_theta - static_cast<std::size_t>(order) * m;
  const double md = static_cast<double>(m);
  AdevPoint p;
  p.m = m;
  p.tau_s = md * tau0_s;
  p.n = n_terms;
  p.adev = std::sqrt(sum / ((order == 3 ? 6.0 : 2.0) * md * md * static_cast<double>(n_terms)));
  if (!std::isfinite(p.adev)) {
    throw DataError("overlapping_adev: the Allan deviation at m = " + std::to_string(m) +
                    " overflows: the values are too large");
  }
  return p;
}

// The noise at this tau decides the interval (Greenhall & Riley 2003). Identified as Stable32
// does (NIST SP 1065 §5.6; noise_id.hpp) in the tau-averaged series: by the lag-1
// autocorrelation where 30 averages remain, by the B1 ratio down to 8; below that carried from the
// largest tau where it was identified, and white FM (the gyro's angle random walk) when the series
// is too short to identify anything. `rate_line`: the rate's line sums, the averages at m = 1.
void assign_noise(AdevPoint& p, BlockAverages& averages, std::span<const double> theta, int order,
                  const LineSums& rate_line, std::optional<int>& last_alpha) {
  const std::size_t n_averages = (theta.size() - 1) / p.m;
  if (n_averages < kMinB1Averages) {
    p.alpha = last_alpha.value_or(0);
    p.noise_id = NoiseIdMethod::none;
    return;
  }
  const std::span<const double> a = averages.at(p.m);
  const auto id = p.m == 1 ? identify_noise_in_averages(a, order, rate_line)
                           : identify_noise_in_averages(a, order);
  if (id) {
    p.alpha = id->alpha;
    p.noise_id = NoiseIdMethod::lag1;
  } else if (const auto b1 = identify_noise_b1_in_averages(a, theta, p.m)) {
    p.alpha = b1->alpha;
    p.noise_id = NoiseIdMethod::b1;
  } else {
    p.alpha = last_alpha.value_or(0);
    p.noise_id = NoiseIdMethod::none;
    return;
  }
  last_alpha = p.alpha;
}

// Reading noise terms off the curve (IEEE Std 952-1997 Annex C, Table C.2). A term whose ADEV
// is c * tau^s shows as a line of slope s on the log-log curve. AVAR is a sum of the
// non-negative AVARs of independent terms, so each term's line lies at or below the curve; its
// coefficient is read as the tangent of slope s from below: c = min over points of sigma/tau^s.
// That equals c where the term dominates, and it is only taken as present when the curve has a
// stretch whose local slope is within kSlopeWindow of s.
constexpr double kSlopeWindow = 0.25;
// Flicker (bias instability) floor: sigma = B sqrt(2 ln 2 / pi) = 0.664 B (IEEE 952 Table C.2).
constexpr double kFlickerFloor = 0.664;

struct CurvePoint {
  double tau_s;
  double adev;
};

// Points usable for reading: positive values and, when an edf is given, at least min_edf.
std::vector<CurvePoint> usable_points(std::span<const AdevPoint> curve, double min_edf) {
  std::vector<CurvePoint> pts;
  for (const AdevPoint& p : curve) {
    const bool edf_ok = p.edf == 0.0 || p.edf >= min_edf;
    if (p.tau_s > 0.0 && p.adev > 0.0 && edf_ok) pts.push_back({p.tau_s, p.adev});
  }
  std::sort(pts.begin(), pts.end(),
            [](const CurvePoint& l, const CurvePoint& r) { return l.tau_s < r.tau_s; });
  return pts;
}

bool has_slope_near(const std::vector<CurvePoint>& pts, double slope) {
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double dlog_tau = std::log(pts[i + 1].tau_s / pts[i].tau_s);
    if (dlog_tau <= 0.0) continue;
    const double local = std::log(pts[i + 1].adev / pts[i].adev) / dlog_tau;
    if (std::fabs(local - slope) <= kSlopeWindow) return true;
  }
  return false;
}

// Coefficient c of the tangent line sigma = c * tau^slope touching the curve from below.
double tangent_coefficient(const std::vector<CurvePoint>& pts, double slope) {
  double c = std::numeric_limits<double>::infinity();
  for (const CurvePoint& p : pts) c = std::min(c, p.adev / std::pow(p.tau_s, slope));
  return c;
}

}  // namespace

std::optional<TauSpacing> tau_spacing_from_name(std::string_view name) {
  if (name == "octave") return TauSpacing::octave;
  if (name == "decade") return TauSpacing::decade;
  if (name == "all") return TauSpacing::all;
  return std::nullopt;
}

std::vector<std::size_t> tau_factors(std::size_t n, TauSpacing spacing) {
  std::vector<std::size_t> out;
  if (n < 3) return out;
  const std::size_t m_max = (n - 1) / 2;  // n - 2m + 1 >= 2
  switch (spacing) {
    case TauSpacing::octave:
      for (std::size_t m = 1; m <= m_max; m *= 2) out.push_back(m);
      break;
    case TauSpacing::decade:
      for (std::size_t decade = 1; decade <= m_max; decade *= 10) {
        for (std::size_t f : {1, 2, 4}) {
          if (f * decade <= m_max) out.push_back(f * decade);
        }
      }
      break;
    case TauSpacing::all:
      for (std::size_t m = 1; m <= m_max; ++m) out.push_back(m);
      break;
  }
  return out;
}

std::pair<double, double> chi_squared_interval(double dev, double edf, double confidence) {
  const double alpha = 1.0 - confidence;
  return {dev * std::sqrt(edf / chi_squared_quantile(1.0 - alpha / 2.0, edf)),
          dev * std::sqrt(edf / chi_squared_quantile(alpha / 2.0, edf))};
}

// Working in sample units, tau0 cancels out of every variance. The mean rate is removed first: AVAR
// is invariant to a constant rate offset (it only adds a linear ramp to theta, which the second
// difference annihilates), and it keeps the cumulative sum a zero-mean random walk, small enough
// for 1e7 samples not to lose precision.
std::vector<double> integrated_angle(std::span<const double> rate) {
  std::vector<double> theta(rate.size() + 1);
  fill_angle(rate, rate_mean(rate, false), theta.data());
  return theta;
}

std::vector<AdevPoint> overlapping_adev(std::span<const double> rate, double rate_hz,
                                        std::span<const std::size_t> m_list, double confidence,
                                        DeviationKind kind) {
  check_adev_arguments(rate_hz, confidence);
  std::vector<AdevPoint> out;
  if (rate.empty()) return out;
  // The angle written once, not zeroed first, the pairs' means beside it.
  const std::span<double> scratch = curve_scratch(rate.size() + 1 + rate.size() / 2);
  LineSums rate_line;
  const double mean = rate_mean_and_line_sums(rate, rate_line);
  fill_angle_and_pairs(rate, mean, scratch.data(), scratch.data() + rate.size() + 1);
  const std::span<const double> theta = scratch.first(rate.size() + 1);
  const int order = kind == DeviationKind::hdev ? 3 : 2;  // the difference taken of the angle
  std::vector<std::size_t> ms;                            // the factors with at least one term
  for (std::size_t m : m_list) {
    if (m != 0 && static_cast<std::size_t>(order) * m < theta.size()) ms.push_back(m);
  }
  const std::vector<double> sums = difference_sums(theta, ms, order);
  BlockAverages averages(rate, scratch.subspan(rate.size() + 1));
  averages.pairs_formed();
  std::optional<int> last_alpha;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    AdevPoint p = deviation_point(sums[i], theta.size(), ms[i], 1.0 / rate_hz, order);
    assign_noise(p, averages, theta, order, rate_line, last_alpha);
    p.edf = greenhall_edf(p.alpha, order, static_cast<double>(ms[i]),
                          static_cast<double>(theta.size()), true);
    std::tie(p.ci_low, p.ci_high) = chi_squared_interval(p.adev, p.edf, confidence);
    out.push_back(p);
  }
  return out;
}

NoiseTerms noise_terms(std::span<const AdevPoint> curve, double min_edf) {
  NoiseTerms out;
  const std::vector<CurvePoint> pts = usable_points(curve, min_edf);
  if (pts.size() < 2) return out;
  // Rate in deg/h, tau in s; 1 (deg/h) * s = 1 arcsec.
  if (has_slope_near(pts, -1.0)) {
    // Quantization: sigma = sqrt(3) Q / tau, so Q[arcsec] = c / sqrt(3).
    out.quantization_arcsec = tangent_coefficient(pts, -1.0) / std::sqrt(3.0);
  }
  if (has_slope_near(pts, -0.5)) {
    // Angle random walk: sigma = N / sqrt(tau); read at tau = 1 s, c is sigma(1 s) in deg/h,
    // and N[deg/sqrt(h)] = c / sqrt(3600 s/h) = c / 60.
    out.angle_random_walk_deg_rth = tangent_coefficient(pts, -0.5) / 60.0;
  }
  if (has_slope_near(pts, 0.0)) {
    const auto min_it =
        std::min_element(pts.begin(), pts.end(),
                         [](const CurvePoint& l, const CurvePoint& r) { return l.adev < r.adev; });
    out.bias_instability_dph = min_it->adev / kFlickerFloor;
    out.bias_instability_tau_s = min_it->tau_s;
  }
  if (has_slope_near(pts, 0.5)) {
    // Rate random walk: sigma = K sqrt(tau / 3) with tau in h. With c = sigma / sqrt(tau_s):
    // K[deg/h/sqrt(h)] = sigma * sqrt(3 / tau_h) = c * sqrt(3 * 3600).
    out.rate_random_walk_dph_rth = tangent_coefficient(pts, 0.5) * std::sqrt(3.0 * 3600.0);
  }
  return out;
}

}  // namespace station::compensation
