// Averaging 1 Hz samples into fixed-width bins (the paper averages 600 s to beat pulse
// quantization).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace station::compensation {

/// Parallel sample series. rate and temp are required; grad and extra may be empty.
struct BinInput {
  std::span<const double> time_s;    ///< sample times, strictly increasing, seconds
  std::span<const double> rate_dph;  ///< gyro rate (or bias), deg/h
  std::span<const double> temp_c;    ///< gyro temperature, deg C
  std::span<const double> grad_c;    ///< temperature gradient inside the gyro, deg C (optional)
  std::span<const double> extra;     ///< any extra channel averaged alongside (optional)
};

/// The paper's bin: 600 s averages beat the pulse quantization of a 1 Hz RLG record.
inline constexpr double kPaperBinS = 600.0;

/// Binning parameters.
struct BinConfig {
  double width_s = kPaperBinS;   ///< bin width w, seconds
  double sample_period_s = 0.0;  ///< nominal sample period; 0 = median of the time steps
  double min_fill = 0.9;         ///< a bin with fewer than min_fill * w / period samples is flagged
};

/// One bin: [t_start_s, t_start_s + width) with its means.
struct Bin {
  double t_start_s = 0;     ///< t0 + k * w
  double t_mid_s = 0;       ///< mean sample time in the bin
  std::size_t n = 0;        ///< samples in the bin
  double rate_dph = 0;      ///< mean rate
  double temp_c = 0;        ///< mean temperature
  double grad_c = 0;        ///< mean gradient (0 when no gradient series)
  double dtdt_c_per_h = 0;  ///< least-squares slope of temperature against time, deg C / h
  double extra = 0;         ///< mean of the extra channel (0 when none)
  double temp_min_c = 0, temp_max_c = 0;  ///< range of the bin's sample temperatures
  double grad_min_c = 0, grad_max_c = 0;  ///< range of its gradients (0 when no series)
  bool complete = false;                  ///< n >= min_fill * expected: usable in fits
};

/// Bin k covers [t0 + k*w, t0 + (k+1)*w), t0 the first sample's time. Only bins that hold a
/// sample are returned, in time order (a gap in the record is a jump in t_start_s, never a run
/// of empty bins): the work and the memory are bounded by the samples, not by the time span.
/// A trailing bin the record does not reach the end of (last time + period < bin end) is
/// dropped. Throws DataError (a std::invalid_argument) on mismatched lengths, non-increasing or
/// non-finite time, a non-finite value, a non-positive width, or a span of more than 2^53 bins.
std::vector<Bin> make_bins(const BinInput& in, const BinConfig& cfg = {});

/// The sample period used for `time_s` under `cfg` (cfg's value, or the median step).
double effective_sample_period_s(std::span<const double> time_s, const BinConfig& cfg);

}  // namespace station::compensation
