// The one place recorded 1 Hz samples become the model's series: which samples count (store.hpp:
// sample_is_usable, sample_goes_into_bins) and what the gradient is (gradient_c), taken together.
#pragma once

#include <vector>

#include "compensation/binning.hpp"
#include "station/store/store.hpp"

namespace station {

/// Which samples a series takes: every usable one, or those in the record window (the bins').
enum class SampleRule { usable, binned };

/// The samples' series: time, gyro rate (Earth rate not subtracted), sensor A temperature and the
/// gradient, °/h and °C.
struct SampleSeries {
  std::vector<double> t_s, rate_dph, temp_c, grad_c;

  /// As the binning's input (compensation/binning.hpp), no channel.
  compensation::BinInput bin_input() const { return {t_s, rate_dph, temp_c, grad_c, {}}; }
};

inline SampleSeries sample_series(const std::vector<SampleRow>& rows,
                                  SampleRule rule = SampleRule::binned) {
  SampleSeries out;
  for (const auto& s : rows) {
    if (rule == SampleRule::binned ? !sample_goes_into_bins(s) : !sample_is_usable(s)) continue;
    out.t_s.push_back(s.t_s);
    out.rate_dph.push_back(*s.rate_dph);
    out.temp_c.push_back(*s.temp_c);
    out.grad_c.push_back(*gradient_c(s));
  }
  return out;
}

}  // namespace station
