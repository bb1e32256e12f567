// Earth rotation rate and its component along a gyro input axis (WGS-84).
#pragma once

#include <optional>
#include <string_view>

namespace station::compensation {

/// WGS-84 angular velocity of the Earth, rad/s (NIMA TR8350.2, Table 3.1).
inline constexpr double kEarthRateRadPerS = 7.292115e-5;
/// The same in deg/h: 7.292115e-5 * 180/pi * 3600 = 15.041067 deg/h.
inline constexpr double kEarthRateDph = kEarthRateRadPerS * 180.0 / 3.14159265358979323846 * 3600.0;

/// Largest |heading| accepted, deg: one turn either way (normalised to [0, 360) after).
inline constexpr double kMaxAbsHeadingDeg = 360.0;

/// A unit vector in the local-level East-North-Up frame.
struct EnuAxis {
  double east = 0;
  double north = 0;
  double up = 1;
};

/// Named input axes: "up", "down", "north", "south", "east", "west". Empty for any other name.
std::optional<EnuAxis> axis_from_name(std::string_view name);

/// Horizontal axis at heading psi (degrees clockwise from north), normalised to [0, 360).
/// Throws DataError unless psi is finite and within +-kMaxAbsHeadingDeg.
EnuAxis horizontal_axis(double heading_deg);

/// An axis as written in configs and options: a name (see axis_from_name) or "heading:DEG".
/// Throws DataError saying what is wrong (unknown name, DEG not a number or out of range).
EnuAxis parse_axis(std::string_view text);

/// The heading of a horizontal axis written as parse_axis reads it ("north", "east", "south",
/// "west", "heading:DEG"), deg clockwise from north in [0, 360); empty for up and down. Throws
/// DataError as parse_axis.
std::optional<double> axis_heading_deg(std::string_view text);

/// The gyro's bias: its output minus the Earth rate along its input axis (the paper, sec. 2: the
/// table holds still, so all a perfect gyro would sense is the Earth's rotation), deg/h.
inline double bias_dph(double rate_dph, double earth_rate_dph) {
  return rate_dph - earth_rate_dph;
}

/// Earth-rate component along `axis` at geodetic latitude `latitude_deg`, deg/h.
/// In ENU the Earth rate is (0, W cos(phi), W sin(phi)) (Titterton & Weston, Strapdown Inertial
/// Navigation Technology, eq. 3.41); the component is its dot product with the (normalized) axis.
/// Throws DataError unless the latitude is finite within [-90, 90] and the axis finite, nonzero.
double earth_rate_along_axis_dph(double latitude_deg, const EnuAxis& axis);

}  // namespace station::compensation
