// Modbus register maps as data, and the codec between engineering values and register words.
// Header-only wire definition: shared by the drivers and by sim_devices (which must not link
// driver classes), so driver and simulator cannot disagree about a register.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace station::drivers::modbus {

/// How a point's register words encode its value.
enum class PointType { int16, uint16, float32 };
/// Order of the two 16-bit words of a float32: ABCD = high word first, CDAB = low word first.
enum class WordOrder { abcd, cdab };
/// Modbus read function code of a point (writes always go to holding registers).
enum class FunctionCode : int { holding = 3, input = 4 };
/// Whether the station may write the point.
enum class Access { ro, rw };

/// One named point of a device's register map.
struct Point {
  std::string name;                               ///< key used by drivers and config
  std::uint16_t address = 0;                      ///< register number as the device manual lists it
  PointType type = PointType::int16;              ///< encoding of the words
  double scale = 1.0;                             ///< engineering value = raw * scale
  WordOrder order = WordOrder::abcd;              ///< float32 word order
  FunctionCode function = FunctionCode::holding;  ///< 3 = holding, 4 = input
  int unit_id = 1;                                ///< Modbus unit (slave) id
  bool one_based = false;                         ///< manual numbers registers from 1
  Access access = Access::ro;                     ///< ro or rw
  /// A process value the device reports as NaN when its input fails (an open sensor): a
  /// non-finite reading reaches the driver as a reading. False: a non-finite value is a
  /// protocol error (a setpoint, a limit, a rate can never legitimately be NaN).
  bool nan_on_input_error = false;

  /// Number of 16-bit registers the point occupies (1 or 2).
  int word_count() const { return type == PointType::float32 ? 2 : 1; }
  /// Address on the wire (PDU address, 0-based).
  std::uint16_t pdu_address() const {
    return one_based ? static_cast<std::uint16_t>(address - 1) : address;
  }
};

/// A device's register map: named points. Lookup of an unknown name throws (setup error).
class RegisterMap {
 public:
  RegisterMap() = default;
  /// Builds a map named `device` (used in error messages) from its points.
  RegisterMap(std::string device, std::vector<Point> points) : device_(std::move(device)) {
    for (auto& p : points) set(std::move(p));
  }
  /// Adds or replaces a point.
  void set(Point p) {
    auto key = p.name;
    points_[key] = std::move(p);
  }
  /// The point named `name`; throws std::invalid_argument naming the map and the point.
  const Point& at(const std::string& name) const {
    auto it = points_.find(name);
    if (it == points_.end())
      throw std::invalid_argument("register map '" + device_ + "': no point named '" + name + "'");
    return it->second;
  }
  /// The point named `name`, or nullptr.
  const Point* find(const std::string& name) const {
    auto it = points_.find(name);
    return it == points_.end() ? nullptr : &it->second;
  }
  /// All points, by name.
  const std::map<std::string, Point>& points() const { return points_; }
  /// Name of the map (device preset), for messages.
  const std::string& device() const { return device_; }

 private:
  std::string device_;
  std::map<std::string, Point> points_;
};

/// Splits an IEEE-754 single into two register words in the given order (done by hand:
/// libmodbus 3.1.6's modbus_set_float_* do not round-trip with its getters).
inline std::array<std::uint16_t, 2> float_to_words(float v, WordOrder order) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  auto hi = static_cast<std::uint16_t>(bits >> 16);
  auto lo = static_cast<std::uint16_t>(bits & 0xFFFFu);
  return order == WordOrder::abcd ? std::array{hi, lo} : std::array{lo, hi};
}

/// Joins two register words (as received, in wire order) into an IEEE-754 single.
inline float words_to_float(const std::uint16_t* w, WordOrder order) {
  std::uint32_t hi = order == WordOrder::abcd ? w[0] : w[1];
  std::uint32_t lo = order == WordOrder::abcd ? w[1] : w[0];
  std::uint32_t bits = (hi << 16) | lo;
  float v = 0;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

/// Decodes a point's words (word_count() of them) into its engineering value.
inline double decode_point(const Point& p, const std::uint16_t* w) {
  switch (p.type) {
    case PointType::int16:
      return static_cast<std::int16_t>(w[0]) * p.scale;
    case PointType::uint16:
      return static_cast<double>(w[0]) * p.scale;
    case PointType::float32:
      return static_cast<double>(words_to_float(w, p.order)) * p.scale;
  }
  return NAN;
}

/// Encodes an engineering value into the point's words; nullopt if it does not fit the type.
inline std::optional<std::array<std::uint16_t, 2>> encode_point(const Point& p, double value) {
  if (!std::isfinite(value) || p.scale == 0) return std::nullopt;
  double raw = value / p.scale;
  if (p.type == PointType::float32) {
    if (std::fabs(raw) > 3.4e38) return std::nullopt;
    return float_to_words(static_cast<float>(raw), p.order);
  }
  double r = std::nearbyint(raw);
  double lo = p.type == PointType::int16 ? -32768.0 : 0.0;
  double hi = p.type == PointType::int16 ? 32767.0 : 65535.0;
  if (r < lo || r > hi) return std::nullopt;
  auto word = static_cast<std::uint16_t>(static_cast<std::int32_t>(r) & 0xFFFF);
  return std::array<std::uint16_t, 2>{word, 0};
}

}  // namespace station::drivers::modbus
