// The Allan deviation floor of a rate series: the minimum of its overlapping ADEV curve, the
// residual bias instability a part file limits (station/parts). IEEE Std 952-1997 Annex C.
#pragma once

#include <optional>
#include <span>

namespace station::compensation {

/// The lowest point of an ADEV curve.
struct AdevFloor {
  double adev = 0;   ///< in the input's rate unit
  double tau_s = 0;  ///< averaging time of that point, s
  double edf = 0;    ///< equivalent degrees of freedom of that point
};

/// Least equivalent degrees of freedom of a point the floor may be read at: with 10, the 68 %
/// interval of the point is about -16 %..+33 % of its value (chi-square interval, NIST SP 1065
/// §5.3); below that, the minimum over octave points would be a low outlier picked by chance.
inline constexpr double kAdevFloorMinEdf = 10.0;

/// Minimum of the overlapping ADEV at octave averaging factors (allan.hpp, tau_factors) over the
/// points with edf >= min_edf. Empty when no point qualifies (too short a series). Throws
/// DataError as overlapping_adev does. Pure.
std::optional<AdevFloor> adev_floor(std::span<const double> rate, double rate_hz,
                                    double min_edf = kAdevFloorMinEdf);

}  // namespace station::compensation
