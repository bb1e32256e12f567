// ADEV floor: the minimum over the well-determined octave points of the overlapping ADEV.
#include "compensation/adev_floor.hpp"

#include "compensation/allan.hpp"

namespace station::compensation {

std::optional<AdevFloor> adev_floor(std::span<const double> rate, double rate_hz, double min_edf) {
  const auto m = tau_factors(rate.size(), TauSpacing::octave);
  if (m.empty()) return std::nullopt;
  std::optional<AdevFloor> best;
  for (const auto& p : overlapping_adev(rate, rate_hz, m)) {
    if (p.edf < min_edf) continue;
    if (!best || p.adev < best->adev) best = AdevFloor{p.adev, p.tau_s, p.edf};
  }
  return best;
}

}  // namespace station::compensation
