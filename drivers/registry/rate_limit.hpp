// A turntable's rate limit as the station holds it: the configured rating (`[turntable]
// max_rate_dps`), lowered to its dialect's own fixed limit where the dialect has one
// (`Dialect::rate_limit_dps`). One rule for the driver's bound on a demand and the start's check
// of a protocol's ladders (station/daemon/acceptance_runner.cpp).
#pragma once

#include <optional>

#include "drivers/registry/dialects.hpp"

namespace station::drivers {

struct TurntableRateLimit {
  double dps = 0;
  bool dialects_own = false;  ///< the dialect's fixed limit, not the configured rating
};

/// Empty: neither the configuration nor the dialect names one (an ACUTROL's is read at connect).
std::optional<TurntableRateLimit> turntable_rate_limit(const DeviceSpec& spec);

}  // namespace station::drivers
