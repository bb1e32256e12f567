// The power-law noise at each averaging time: which of white PM (alpha +2), flicker PM (+1),
// white FM (0, angle random walk), flicker FM (-1, bias instability) or random-walk FM (-2, rate
// random walk) dominates, alpha being the exponent of the rate's power spectral density
// S(f) ~ f^alpha. The interval of a deviation needs it (noise_edf.hpp). Two methods, as Stable32
// uses them (NIST SP 1065, Riley 2008, §5.6 "Noise Identification"):
//
// Lag-1 autocorrelation (Riley & Greenhall, "Power law noise identification using the lag 1
// autocorrelation", Proc. 18th EFTF, 2004): the rate averaged in non-overlapping blocks of m, a
// line removed, differenced d times until delta = r1 / (1 + r1) < 0.25 (or d = d_max: 2 for the
// Allan, 3 for the Hadamard variance); alpha = -round(2 delta) - 2 d. Needs about 30 averages.
//
// B1 ratio (Barnes, "Tables of bias functions, B1 and B2, for variances based on finite samples
// of processes with power law spectral densities", NBS Technical Note 375, 1969; Howe, Beard,
// Greenhall, Riley, "A total estimator of the Hadamard function used for GPS operations", Proc.
// 32nd PTTI, 2000, Table 3) where fewer averages remain: the standard variance of the N averages
// over their Allan variance, against its expectation B1(N, mu) for each tau exponent mu of the
// Allan variance; mu = -2 for both PM noises, which the ratio R(n) = Mod AVAR / AVAR then tells
// apart (Allan & Barnes, "A modified Allan variance with increased oscillator characterization
// ability", Proc. 35th FCS, 1981, Fig. 2, reprinted in NIST TN 1337). Unlike Stable32, the station
// also lets R(n) overrule B1's PM where it is nearer white FM's expectation: B1 alone reads white
// FM as PM in 29 % of series with 10 averages, which would give it 4 to 34 times its edf.
// docs/UNCERTAINTY.md gives the measured agreement with Stable32.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "compensation/vector_sums.hpp"

namespace station::compensation {

/// Averages the lag-1 method needs (Riley & Greenhall 2004: about 30).
inline constexpr std::size_t kMinNoiseIdPoints = 30;
/// Averages the B1 ratio is used down to. Stable32 identifies nothing below 8 averages for its
/// overlapping deviations (it keeps the last alpha; docs/UNCERTAINTY.md), nor does the station.
inline constexpr std::size_t kMinB1Averages = 8;

/// Which method identified the noise at one averaging time.
enum class NoiseIdMethod {
  lag1,  ///< lag-1 autocorrelation, at least kMinNoiseIdPoints averages
  b1,    ///< B1 ratio (and R(n) for the PM noises), kMinB1Averages up to kMinNoiseIdPoints
  none,  ///< neither: fewer than kMinB1Averages averages
};

/// "lag1", "b1" or "none" (the value `station adev --json` reports).
std::string_view noise_id_method_name(NoiseIdMethod method);

/// What the lag-1 method found at one averaging factor.
struct NoiseId {
  int alpha = 0;         ///< integer power-law exponent of the rate's PSD, +2 .. -2 (-4 for HDEV)
  double alpha_est = 0;  ///< the unrounded estimate -2 (delta + d)
  int differences = 0;   ///< d
};

/// The means of the floor(n / m) whole non-overlapping blocks of m rate samples (the tau-averaged
/// series the noise is identified in), for factors asked in increasing order. A factor's
/// averages are formed from those of the previous factor when it divides m (octave taus: pairs
/// of the previous averages, all of them one pass over the rate and n values of memory), else
/// from the rate (m = 1: the rate itself). Holds a view of `rate`.
class BlockAverages {
 public:
  explicit BlockAverages(std::span<const double> rate) : rate_(rate) {}
  /// The same, the averages written into `scratch` (rate.size() / 2 values or more: what any
  /// m >= 2 needs) rather than into memory of its own; holds a view of both.
  BlockAverages(std::span<const double> rate, std::span<double> scratch)
      : rate_(rate), scratch_(scratch) {}
  /// Says that the scratch already holds the averages at factor 2, formed as at(2) would form
  /// them ((y_2b + y_2b+1) / 2, b < rate.size() / 2): a caller's pass over the rate wrote them.
  void pairs_formed();
  /// The averages at factor m (>= 1, not below the previous call's); valid until the next call.
  std::span<const double> at(std::size_t m);

 private:
  std::span<const double> rate_;
  std::span<double> scratch_;      // the caller's memory for the averages, if it gave any
  std::unique_ptr<double[]> own_;  // else memory of its own, written once (not zeroed first)
  double* last_ = nullptr;         // the averages of factor m_, in one of the two
  std::size_t m_ = 1;              // 1: the rate itself
  std::size_t size_ = 0;           // how many
};

/// identify_noise on the averages a BlockAverages formed; empty below kMinNoiseIdPoints of them.
std::optional<NoiseId> identify_noise_in_averages(std::span<const double> averages, int d_max);
/// The same with the averages' line sums (vector_sums.hpp, line_sums) already taken.
std::optional<NoiseId> identify_noise_in_averages(std::span<const double> averages, int d_max,
                                                  const LineSums& sums);

/// Identifies the dominant power-law noise of `rate` at averaging factor m by the lag-1 method;
/// empty when fewer than kMinNoiseIdPoints averages remain. `d_max` is 2 for ADEV, 3 for HDEV.
/// The result is clamped to the range the variance converges for (-2 .. +2 for ADEV). Pure.
std::optional<NoiseId> identify_noise(std::span<const double> rate, std::size_t m, int d_max);

/// Barnes' B1(N, mu): the expected ratio of the N-sample (standard) variance to the Allan variance
/// for a noise whose Allan variance goes as tau^mu (no dead time). N >= 2.
double b1_expected(double n_averages, int mu);

/// The expected R(n) = Mod AVAR / AVAR at averaging factor m for white PM (alpha 2), flicker PM
/// (alpha 1; measurement bandwidth the Nyquist frequency 1 / (2 tau0)) or white FM (alpha 0).
double rn_expected(int alpha, double m);

/// What the B1 ratio found at one averaging factor.
struct B1Id {
  int alpha = 0;             ///< +2 .. -2
  double b1 = 0;             ///< the measured ratio
  std::optional<double> rn;  ///< the measured R(n), when the B1 ratio said PM
  std::size_t averages = 0;  ///< N
};

/// Identifies the dominant noise of `rate` at averaging factor m by the B1 ratio and, where B1
/// says PM, R(n): white PM, flicker PM, or white FM that B1 mistook for PM. Empty when fewer than
/// kMinB1Averages averages remain or the Allan variance is 0. Pure.
std::optional<B1Id> identify_noise_b1(std::span<const double> rate, std::size_t m);

/// identify_noise_b1 on the averages at factor m that a BlockAverages formed, with `theta` the
/// integrated angle of the rate (allan.hpp, integrated_angle) for R(n).
std::optional<B1Id> identify_noise_b1_in_averages(std::span<const double> averages,
                                                  std::span<const double> theta, std::size_t m);

}  // namespace station::compensation
