// What a device reading may be: the one rule that tells a value from a reading no device of its
// dialect could give (issue 34). Each dialect declares its range from its source
// (Chamber::air_range_c, Turntable::rate_range_dps; docs/DEVICES.md, "Plausible readings"); the
// station narrows it by its configuration (station/daemon/plausibility.cpp) and applies it. No I/O.
#pragma once

#include <cmath>
#include <limits>
#include <optional>

namespace station::drivers {

/// The closed interval a device can physically report, in the quantity's unit.
struct PlausibleRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  /// The narrower of this range and `o`.
  PlausibleRange operator&(const PlausibleRange& o) const {
    return {std::fmax(lo, o.lo), std::fmin(hi, o.hi)};
  }
};

/// The bound `v` breaks, or std::nullopt when it is a reading: a value that is not a number, or
/// one too small to be a normal 32-bit float yet not 0 (a float32 subnormal: no sensor's reading
/// but the mark of words taken for a float that is none, e.g. 0x8000 0x8000 read as -4.6e-41)
/// breaks the range as a whole (its value returned), one outside [lo, hi] the end it passed.
inline std::optional<double> broken_bound(double v, const PlausibleRange& r) {
  if (!std::isfinite(v) || (v != 0 && std::fabs(v) < std::numeric_limits<float>::min())) return v;
  if (v < r.lo) return r.lo;
  if (v > r.hi) return r.hi;
  return std::nullopt;
}

}  // namespace station::drivers
