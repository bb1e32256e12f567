#include "compensation/noise_id.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "compensation/allan.hpp"
#include "compensation/vector_sums.hpp"

namespace station::compensation {
namespace {

/// The mean of the q values at p: four partial sums, so a long block does not wait on one add.
double block_mean(const double* p, std::size_t q) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  std::size_t i = 0;
  for (; i + 4 <= q; i += 4) {
    s0 += p[i];
    s1 += p[i + 1];
    s2 += p[i + 2];
    s3 += p[i + 3];
  }
  for (; i < q; ++i) s0 += p[i];
  return ((s0 + s1) + (s2 + s3)) / static_cast<double>(q);
}

/// The least-squares line a + b t of y against t = 0 .. n-1.
struct Line {
  double icpt = 0, slope = 0;
};

/// Sum t and sum t^2 over t = 0 .. n-1 in closed form (n (n-1) / 2, (n-1) n (2n-1) / 6), sum y
/// and sum t y by vector_sums.hpp.
Line least_squares_line(std::size_t n_values, const LineSums& sums) {
  const double n = static_cast<double>(n_values);
  const double st = n * (n - 1) / 2, stt = (n - 1) * n * (2 * n - 1) / 6;
  const double den = n * stt - st * st;
  Line line;
  line.slope = den != 0 ? (n * sums.ty - st * sums.y) / den : 0.0;
  line.icpt = (sums.y - line.slope * st) / n;
  return line;
}

/// y minus its least-squares line.
std::vector<double> detrended(std::span<const double> y, const Line& line) {
  std::vector<double> x(y.size());
  for (std::size_t i = 0; i < y.size(); ++i)
    x[i] = y[i] - (line.icpt + line.slope * static_cast<double>(i));
  return x;
}

/// The lag-1 autocorrelation (Riley & Greenhall 2004, eq. 2) of x = y minus its line, in one pass
/// over y (vector_sums.hpp): sums of x, x^2 and x_t x_{t+1}, the mean taken out afterwards by
/// sum (x - mu)^2 = sum x^2 - mu sum x and
/// sum (x_t - mu)(x_{t+1} - mu) = sum x_t x_{t+1} - mu (2 sum x - x_0 - x_{n-1}) + (n - 1) mu^2.
/// The mean of a least-squares residual is 0 but for rounding, so neither correction cancels.
double lag1_about_line(std::span<const double> y, const Line& line) {
  const std::size_t n = y.size();
  const LagSums s = residual_lag_sums(y, line.icpt, line.slope);
  const double x0 = y[0] - line.icpt;
  const double x_last = y[n - 1] - (line.icpt + line.slope * static_cast<double>(n - 1));
  const double mu = s.x / static_cast<double>(n);
  const double den = s.xx - mu * s.x;
  const double num = s.x_next - mu * (2 * s.x - x0 - x_last) + static_cast<double>(n - 1) * mu * mu;
  return den > 0 ? num / den : 0.0;
}

/// Lag-1 autocorrelation about the mean (Riley & Greenhall 2004, eq. 2).
double lag1(std::span<const double> x) {
  double mean = 0;
  for (const double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double num = 0, den = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    den += (x[i] - mean) * (x[i] - mean);
    if (i + 1 < x.size()) num += (x[i] - mean) * (x[i + 1] - mean);
  }
  return den > 0 ? num / den : 0.0;
}

/// The standard (N-sample) variance, N - 1 in the denominator (NIST SP 1065 §5.2.1).
double standard_variance(std::span<const double> a) {
  double mean = 0;
  for (const double v : a) mean += v;
  mean /= static_cast<double>(a.size());
  double ss = 0;
  for (const double v : a) ss += (v - mean) * (v - mean);
  return ss / static_cast<double>(a.size() - 1);
}

/// The non-overlapping Allan variance of the averages a_j at their tau (NIST SP 1065 §5.2.2):
/// sum (a_{j+1} - a_j)^2 / (2 (N - 1)). Stable32 divides by this one in B1, for its overlapping
/// deviations too (docs/UNCERTAINTY.md); it also makes the better ratio: computed from the same
/// N averages as the standard variance, it is correlated with it, and at 10 averages of white FM
/// the ratio finds white FM in 52.2 % of series where the overlapping AVAR's finds 44.2 %
/// (100,000 seeded series of 1,000 samples, m = 100).
double allan_variance_of_averages(std::span<const double> a) {
  double ss = 0;
  for (std::size_t j = 0; j + 1 < a.size(); ++j) ss += (a[j + 1] - a[j]) * (a[j + 1] - a[j]);
  return ss / (2.0 * static_cast<double>(a.size() - 1));
}

/// The overlapping modified Allan variance at averaging factor m (NIST SP 1065 §5.2.5):
/// 1 / (2 m^2 tau^2 (N - 3m + 1)) sum_j (sum_{i=j}^{j+m-1} x_{i+2m} - 2 x_{i+m} + x_i)^2 over the
/// N = n + 1 phase points x = tau0 theta, theta the integrated rate (tau0^2 cancels with tau).
/// Needs n >= 3m.
double modified_allan_variance(std::span<const double> theta, std::size_t m) {
  const auto d2 = [&](std::size_t i) { return theta[i + 2 * m] - 2 * theta[i + m] + theta[i]; };
  const std::size_t terms = theta.size() - 3 * m + 1;
  double inner = 0;
  for (std::size_t i = 0; i < m; ++i) inner += d2(i);
  double sum = inner * inner;
  for (std::size_t j = 1; j < terms; ++j) {
    inner += d2(j + m - 1) - d2(j - 1);  // slide the inner sum by one phase point
    sum += inner * inner;
  }
  const double md = static_cast<double>(m);
  return sum / (2.0 * md * md * md * md * static_cast<double>(terms));
}

/// The Allan variance's tau exponent mu whose expected B1 is nearest to the measured one: the
/// boundaries lie at the geometric means of neighbouring expectations. With them (and B1(N, mu)
/// taken at Stable32's count of terms in place of N) this ratio reproduces Stable32's alpha at
/// every B1 tau of its outputs we have; with arithmetic means it does not (docs/UNCERTAINTY.md).
/// allantools (ci.py, b1_boundary) and allantoolkit (noise_id.py, b1_noise_id, after Howe et al.
/// 2000, Table 4) take geometric means too.
int mu_from_b1(double b1, double n_averages) {
  for (int mu = 1; mu > -2; --mu) {
    const double boundary =
        std::sqrt(b1_expected(n_averages, mu) * b1_expected(n_averages, mu - 1));
    if (b1 > boundary) return mu;
  }
  return -2;
}

/// Where B1 says PM (mu = -2): white PM, flicker PM or white FM by the measured R(n), the
/// boundaries at the geometric means of neighbouring expectations (white PM < flicker PM < white
/// FM from m = 3 on; allantools' rn_boundary and allantoolkit's rn_noise_id take geometric means
/// between the two PM noises). Stable32 splits the PM noises only; the third expectation lets R(n)
/// overrule a PM that B1 read in white FM (docs/UNCERTAINTY.md). Below m = 3 the expectations
/// cross (at m = 1 Mod AVAR is AVAR for every noise) and R(n) tells nothing: white PM is taken,
/// whose Greenhall edf is there the smallest of the three (8.5, 10.4, 12.7 at m = 1 from 17
/// samples): the widest, conservative interval.
int pm_by_rn(double rn, double m) {
  if (m < 3) return 2;
  if (rn > std::sqrt(rn_expected(1, m) * rn_expected(0, m))) return 0;
  return rn < std::sqrt(rn_expected(1, m) * rn_expected(2, m)) ? 2 : 1;
}

}  // namespace

std::string_view noise_id_method_name(NoiseIdMethod method) {
  switch (method) {
    case NoiseIdMethod::lag1:
      return "lag1";
    case NoiseIdMethod::b1:
      return "b1";
    case NoiseIdMethod::none:
      break;
  }
  return "none";
}

void BlockAverages::pairs_formed() {
  last_ = scratch_.data();
  size_ = rate_.size() / 2;
  m_ = 2;
}

std::span<const double> BlockAverages::at(std::size_t m) {
  if (m <= 1) return rate_;
  if (m == m_) return {last_, size_};
  const bool from_last = m_ > 1 && m % m_ == 0;
  const std::span<const double> src = from_last ? std::span<const double>(last_, size_) : rate_;
  const std::size_t q = from_last ? m / m_ : m;
  const std::size_t blocks = src.size() / q;
  if (!from_last && blocks <= scratch_.size()) {
    last_ = scratch_.data();
  } else if (!from_last) {
    own_ = std::make_unique_for_overwrite<double[]>(blocks);
    last_ = own_.get();
  }
  // In place when formed from last_: block b reads q >= 2 values from index b q >= b on.
  double* out = last_;
  if (q == 2) {  // octave taus: the same bits as block_mean, in a loop that vectorises
    for (std::size_t b = 0; b < blocks; ++b) out[b] = (src[2 * b] + src[2 * b + 1]) / 2.0;
  } else {
    for (std::size_t b = 0; b < blocks; ++b) out[b] = block_mean(src.data() + b * q, q);
  }
  size_ = blocks;
  m_ = m;
  return {last_, size_};
}

std::optional<NoiseId> identify_noise_in_averages(std::span<const double> averages, int d_max) {
  if (averages.size() < kMinNoiseIdPoints) return std::nullopt;
  return identify_noise_in_averages(averages, d_max, line_sums(averages));
}

std::optional<NoiseId> identify_noise_in_averages(std::span<const double> averages, int d_max,
                                                  const LineSums& sums) {
  if (averages.size() < kMinNoiseIdPoints) return std::nullopt;
  const Line line = least_squares_line(averages.size(), sums);
  double r1 = lag1_about_line(averages, line);
  std::vector<double> x;  // the differenced series, formed only when a difference is taken
  for (int d = 0;; ++d) {
    const double delta = r1 / (1 + r1);
    if (delta < 0.25 || d >= d_max) {
      NoiseId id;
      id.differences = d;
      id.alpha_est = -2 * (delta + d);
      id.alpha = static_cast<int>(-std::lround(2 * delta)) - 2 * d;
      // The variance of order d_max converges for alpha > 1 - 2 d_max; white PM (+2) at most.
      id.alpha = std::clamp(id.alpha, 2 - 2 * d_max, 2);
      return id;
    }
    if (d == 0) x = detrended(averages, line);
    for (std::size_t i = 0; i + 1 < x.size(); ++i) x[i] = x[i + 1] - x[i];
    x.pop_back();
    r1 = lag1(x);
  }
}

std::optional<NoiseId> identify_noise(std::span<const double> rate, std::size_t m, int d_max) {
  if (m == 0 || rate.size() / m < kMinNoiseIdPoints) return std::nullopt;
  BlockAverages averages(rate);
  return identify_noise_in_averages(averages.at(m), d_max);
}

double b1_expected(double n_averages, int mu) {
  const double n = n_averages;
  // mu = 0 (flicker FM): the limit of the general form, N ln N / (2 (N - 1) ln 2).
  if (mu == 0) return n * std::log(n) / (2.0 * (n - 1.0) * std::numbers::ln2);
  // Barnes, NBS TN 375 (1969); Howe et al. 2000, Table 3 (r = 1, no dead time):
  // B1(N, mu) = N (1 - N^mu) / (2 (N - 1) (1 - 2^mu)).
  return n * (1.0 - std::pow(n, mu)) / (2.0 * (n - 1.0) * (1.0 - std::pow(2.0, mu)));
}

double rn_expected(int alpha, double m) {
  // White PM: Mod AVAR / AVAR = 1 / n (Allan & Barnes 1981, Fig. 2: Mod AVAR falls as tau^-3
  // where AVAR falls as tau^-2, and the two are equal at n = 1).
  if (alpha == 2) return 1.0 / m;
  // White FM (unit variance per sample): the weights the Mod AVAR estimator's inner sum puts on
  // the samples square-sum to m^3 + m, so Mod AVAR = (m^3 + m) / (2 m^4) against AVAR = 1/m:
  // R = 1/2 + 1/(2 m^2) exactly, tending to the 1/2 of IEEE Std 1139-2008's table (Mod AVAR
  // h0 / (4 tau), AVAR h0 / (2 tau)).
  if (alpha == 0) return 0.5 + 0.5 / (m * m);
  // Flicker PM, IEEE Std 1139-2008's table of the power-law variances: AVAR = h1 (1.038 +
  // 3 ln(2 pi f_h tau)) / (4 pi^2 tau^2), Mod AVAR = h1 3 ln(256/27) / (8 pi^2 tau^2) (large n).
  // With f_h = 1 / (2 tau0), 2 pi f_h tau = pi m, and the ratio is
  // 1.5 ln(256/27) / (1.038 + 3 ln(pi m)) (allantoolkit's rn_expected has the same, rounded to
  // 3.37 / (1.04 + 3 ln(pi m)), from NIST TN 1337 §A-6, Table 2).
  return 1.5 * std::log(256.0 / 27.0) / (1.038 + 3.0 * std::log(std::numbers::pi * m));
}

std::optional<B1Id> identify_noise_b1_in_averages(std::span<const double> a,
                                                  std::span<const double> theta, std::size_t m) {
  if (m == 0 || a.size() < kMinB1Averages) return std::nullopt;
  const double avar = allan_variance_of_averages(a);
  if (!(avar > 0.0)) return std::nullopt;
  B1Id id;
  id.averages = a.size();
  id.b1 = standard_variance(a) / avar;  // SP 1065 §5.6: the B1 ratio
  const int mu = mu_from_b1(id.b1, static_cast<double>(a.size()));
  id.alpha = -mu - 1;  // the FM noises: AVAR ~ tau^mu with mu = -alpha - 1 (SP 1065 §5.6)
  if (mu > -2) return id;
  id.rn = modified_allan_variance(theta, m) / avar;
  id.alpha = pm_by_rn(*id.rn, static_cast<double>(m));
  return id;
}

std::optional<B1Id> identify_noise_b1(std::span<const double> rate, std::size_t m) {
  if (m == 0 || rate.size() / m < kMinB1Averages) return std::nullopt;
  BlockAverages averages(rate);
  return identify_noise_b1_in_averages(averages.at(m), integrated_angle(rate), m);
}

}  // namespace station::compensation
