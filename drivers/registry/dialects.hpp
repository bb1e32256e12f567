// The one table of device dialects (gpsd's driver table): each chamber and turntable model the
// station speaks, its transport and how to build its driver. Adding a dialect is its folder under
// drivers/chamber/ or drivers/turntable/, one line in dialects.cpp, its simulator face and
// docs/DEVICES.md.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/ascii/line_endpoint.hpp"
#include "drivers/ascii/line_wire.hpp"
#include "drivers/chamber/chamber.hpp"
#include "drivers/common/clock.hpp"
#include "drivers/common/tap.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/modbus/map_overrides.hpp"
#include "drivers/modbus/modbus_wire.hpp"
#include "drivers/modbus/readback.hpp"
#include "drivers/modbus/register_map.hpp"
#include "drivers/turntable/turntable.hpp"

namespace station::drivers {

/// How a dialect reaches its device.
enum class Transport { modbus, ascii };

/// A configured device: which model, where, and the knobs its dialect reads.
struct DeviceSpec {
  std::string name;      ///< "chamber", "turntable": logs, records, tap device
  std::string model;     ///< a dialect name (or alias)
  std::string endpoint;  ///< tcp://H:P, rtu:/dev/X?... (Modbus), serial:/dev/X?... (ASCII)
  int unit_id = 1;       ///< Modbus unit id, or an ASCII unit's RS-485 address
  double timeout_s = 0.5;
  int readback_every = modbus::ReadbackSchedule::kDefaultEvery;
  std::vector<modbus::PointOverride> overrides;  ///< Modbus dialects: point overrides
  int run_event = 1;  ///< Watlow F4/F4T: event output that runs the chamber (builder's wiring)
  /// ASCII dialects with a choice of reply framing (the row's `framings`): "" is the default.
  std::string framing;
};

/// Makes the link under a device's client (replay passes recorded ones); empty: the real link.
using ModbusWireFactory = std::function<std::unique_ptr<modbus::ModbusWire>(
    const std::string& device, const modbus::Endpoint& endpoint)>;
using LineWireFactory = std::function<std::unique_ptr<ascii::LineWire>(
    const std::string& device, const ascii::LineEndpoint& endpoint)>;

/// What every driver is built with besides its spec.
struct LinkOptions {
  Tap* tap = nullptr;             ///< every exchange passes here when set
  const Clock* clock = nullptr;   ///< reconnect back-off time (nullptr: steady clock)
  ModbusWireFactory modbus_wire;  ///< empty: libmodbus
  LineWireFactory line_wire;      ///< empty: FdLineWire
};

/// One dialect of a device class.
template <typename Device>
struct Dialect {
  std::string_view model;  ///< config name, e.g. "watlow_f4t"
  Transport transport;
  std::string_view summary;  ///< one line for `--help` and errors
  /// Other names the configuration accepts for it (old preset names), comma-separated.
  std::string_view aliases;
  /// Whether the controller has event outputs (Watlow F4/F4T): `run_event` is then allowed.
  bool event_outputs;
  /// The wire map a Modbus dialect's overrides apply to (empty for ASCII dialects).
  std::function<modbus::RegisterMap(const DeviceSpec&)> map;
  /// Builds the driver; no I/O. Throws std::invalid_argument on a bad spec.
  std::function<std::unique_ptr<Device>(const DeviceSpec&, const LinkOptions&)> make;
  /// The reply framings `framing` may name, comma-separated, the first the default (empty: the
  /// key is not taken).
  std::string_view framings = {};
};

using ChamberDialect = Dialect<Chamber>;
using TurntableDialect = Dialect<Turntable>;

/// Every dialect, in the order `--help` lists them.
std::span<const ChamberDialect> chamber_dialects();
std::span<const TurntableDialect> turntable_dialects();
/// The dialect named `model` (or an alias: "f4t" for watlow_f4t); throws std::invalid_argument
/// naming the model and listing the known ones.
const ChamberDialect& chamber_dialect(std::string_view model);
const TurntableDialect& turntable_dialect(std::string_view model);
/// Checks a spec without building anything: model known, endpoint of the dialect's transport,
/// overrides valid on its map; throws std::invalid_argument naming what is wrong.
template <typename Device>
void validate(const Dialect<Device>& dialect, const DeviceSpec& spec);
/// "a, b, c" of the model names.
std::string chamber_models();
std::string turntable_models();

}  // namespace station::drivers
