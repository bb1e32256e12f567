// Earth-rate component along an input axis.
#include "compensation/earth_rate.hpp"

#include <cmath>
#include <numbers>

namespace station::compensation {

std::optional<EnuAxis> axis_from_name(std::string_view name) {
  if (name == "up") return EnuAxis{0, 0, 1};
  if (name == "down") return EnuAxis{0, 0, -1};
  if (name == "north") return EnuAxis{0, 1, 0};
  if (name == "south") return EnuAxis{0, -1, 0};
  if (name == "east") return EnuAxis{1, 0, 0};
  if (name == "west") return EnuAxis{-1, 0, 0};
  return std::nullopt;
}

EnuAxis horizontal_axis(double heading_deg) {
  const double psi = heading_deg * std::numbers::pi / 180.0;
  return EnuAxis{std::sin(psi), std::cos(psi), 0};
}

double earth_rate_along_axis_dph(double latitude_deg, const EnuAxis& axis) {
  const double phi = latitude_deg * std::numbers::pi / 180.0;
  const double norm =
      std::sqrt(axis.east * axis.east + axis.north * axis.north + axis.up * axis.up);
  // Omega_ENU = W (0, cos phi, sin phi); the east component is zero.
  const double along = axis.north * std::cos(phi) + axis.up * std::sin(phi);
  return kEarthRateDph * along / norm;
}

}  // namespace station::compensation
