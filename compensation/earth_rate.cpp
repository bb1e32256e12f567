// Earth-rate component along an input axis.
#include "compensation/earth_rate.hpp"

#include <charconv>
#include <cmath>
#include <numbers>
#include <string>

#include "compensation/limits.hpp"

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

namespace {

// A heading within +-kMaxAbsHeadingDeg normalised to [0, 360); throws DataError beyond.
double normalized_heading_deg(double heading_deg) {
  if (!std::isfinite(heading_deg) || std::abs(heading_deg) > kMaxAbsHeadingDeg) {
    throw DataError("heading " + number_text(heading_deg) + " is not within +-360 deg");
  }
  double psi_deg = std::fmod(heading_deg, 360.0);  // exact
  if (psi_deg < 0) psi_deg += 360.0;
  if (psi_deg >= 360.0) psi_deg = 0.0;  // -tiny + 360 rounds to 360
  return psi_deg;
}

}  // namespace

EnuAxis horizontal_axis(double heading_deg) {
  const double psi_deg = normalized_heading_deg(heading_deg);
  const double psi = psi_deg * std::numbers::pi / 180.0;
  return EnuAxis{std::sin(psi), std::cos(psi), 0};
}

EnuAxis parse_axis(std::string_view text) {
  if (auto named = axis_from_name(text)) return *named;
  constexpr std::string_view kHeading = "heading:";
  if (text.substr(0, kHeading.size()) != kHeading) {
    throw DataError("unknown axis '" + std::string(text) +
                    "' (expected up, down, north, south, east, west or heading:DEG)");
  }
  const std::string_view deg = text.substr(kHeading.size());
  double v = 0;
  const auto [ptr, ec] = std::from_chars(deg.data(), deg.data() + deg.size(), v);
  if (deg.empty() || ec == std::errc::invalid_argument || ptr != deg.data() + deg.size()) {
    throw DataError("heading '" + std::string(deg) + "' is not a number of degrees");
  }
  if (ec == std::errc::result_out_of_range || !std::isfinite(v) ||
      std::abs(v) > kMaxAbsHeadingDeg) {
    throw DataError("heading " + std::string(deg) + " is not within +-360 deg");
  }
  return horizontal_axis(v);
}

std::optional<double> axis_heading_deg(std::string_view text) {
  const EnuAxis a = parse_axis(text);  // validates
  if (a.up != 0.0) return std::nullopt;
  if (text == "north") return 0.0;
  if (text == "east") return 90.0;
  if (text == "south") return 180.0;
  if (text == "west") return 270.0;
  // "heading:DEG", DEG read as parse_axis read it (exact: no round trip through sin and cos).
  const std::string_view deg = text.substr(text.find(':') + 1);
  double v = 0;
  std::from_chars(deg.data(), deg.data() + deg.size(), v);
  return normalized_heading_deg(v);
}

double earth_rate_along_axis_dph(double latitude_deg, const EnuAxis& axis) {
  if (!(latitude_deg >= -90.0 && latitude_deg <= 90.0)) {
    throw DataError("latitude " + number_text(latitude_deg) + " deg is not within -90..90");
  }
  const double norm =
      std::sqrt(axis.east * axis.east + axis.north * axis.north + axis.up * axis.up);
  if (!(norm > 0) || !std::isfinite(norm)) throw DataError("input axis is zero or not finite");
  const double phi = latitude_deg * std::numbers::pi / 180.0;
  // Omega_ENU = W (0, cos phi, sin phi); the east component is zero.
  const double along = axis.north * std::cos(phi) + axis.up * std::sin(phi);
  return kEarthRateDph * along / norm;
}

}  // namespace station::compensation
