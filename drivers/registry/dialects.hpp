// The one table of device dialects (gpsd's driver table): each chamber and turntable model the
// station speaks, its transport and how to build its driver. Adding a dialect is its folder under
// drivers/chamber/ or drivers/turntable/, one line in dialects.cpp, its simulator face and
// docs/DEVICES.md.
#pragma once

#include <functional>
#include <memory>
#include <optional>
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

/// How long a dialect waits for a reply and rests between requests: the station's defaults, each
/// with its source beside its row (dialects.cpp) and in docs/DEVICES.md ("Timing"). The
/// configuration's timeout_s and request_gap_s override them.
struct LinkTiming {
  double timeout_s = 0.5;           ///< bound on one transaction, s
  double serial_request_gap_s = 0;  ///< Modbus: quiet between requests on a serial line, s
};

/// A configured device: which model, where, and the knobs its dialect reads.
struct DeviceSpec {
  std::string name;        ///< "chamber", "turntable": logs, records, tap device
  std::string model;       ///< a dialect name (or alias)
  std::string endpoint;    ///< tcp://H:P, rtu:/dev/X?... (Modbus), serial:/dev/X?... (ASCII)
  int unit_id = 1;         ///< Modbus unit id, or an ASCII unit's RS-485 address
  double timeout_s = 0.5;  ///< bound on one transaction, s (configured: the dialect's by default)
  /// Modbus: quiet kept between one exchange and the next request, s (configured: the dialect's
  /// for the unit's link by default, default_request_gap_s()).
  double request_gap_s = 0;
  /// Modbus: every float register's word order as the unit's panel sets it (unset: the map's).
  std::optional<modbus::WordOrder> word_order;
  /// Modbus TCP: the endpoint is a TCP-to-RTU gateway and the unit sits on its serial line; the
  /// dialect reads it as a serial unit (F4T: units register 14080, the serial pause).
  bool gateway = false;
  int readback_every = modbus::ReadbackSchedule::kDefaultEvery;
  /// Modbus TCP: the most reads of one device reading on the wire at once (ModbusClient::
  /// set_pipeline); 1, the default: one request, its reply, then the next (what every unit serves).
  int modbus_pipeline = 1;
  std::vector<modbus::PointOverride> overrides;  ///< Modbus dialects: point overrides
  int run_event = 1;  ///< Watlow F4/F4T: event output that runs the chamber (builder's wiring)
  /// Watlow F4/F4T: the input (F4) or loop (F4T) carrying the product temperature; 0: none. An
  /// explicit choice: a humidity input is never read as a temperature (docs/DEVICES.md).
  int product_input = 0;
  /// Watlow F4/F4T: the event output wired to humidity (TestEquity: event 2), kept off during a
  /// run on a humidity chamber; 0: none.
  int humidity_event = 2;
  /// The chamber's setpoint limits, °C, where the unit serves none (F4T Data Map 2).
  std::optional<double> setpoint_low_c, setpoint_high_c;
  /// ASCII dialects with a choice of reply framing (the row's `framings`): "" is the default.
  std::string framing;
  /// [turntable]: the table's rate and acceleration limits (its maker's rating, or the unit's
  /// setting), deg/s and deg/s^2; unset: the dialect's (`Dialect::rate_limit_dps`) or none. The
  /// start refuses a protocol asking beyond them (station/daemon/acceptance_runner.hpp).
  std::optional<double> max_rate_dps, max_accel_dps2;
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
  /// The highest input (F4) or loop (F4T) `product_input` may name (0: the key is not taken).
  int product_inputs = 0;
  /// Reply timeout and serial pause (LinkTiming; sources in dialects.cpp).
  LinkTiming timing{};
  /// The reply framings `framing` may name, comma-separated, the first the default (empty: the
  /// key is not taken).
  std::string_view framings = {};
  /// A turntable dialect's fixed rate limit, deg/s, where it has one (the station's own map:
  /// its driver refuses a demand beyond it); unset: the unit's own (read at connect) or none.
  std::optional<double> rate_limit_dps = {};
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
/// Whether the unit of a Modbus `spec` sits on a serial line: an rtu: endpoint, or behind a
/// gateway. Throws std::invalid_argument for an endpoint that is not Modbus.
bool serial_unit(const DeviceSpec& spec);
/// The pause `spec` gets when the configuration sets none: the dialect's serial pause for a unit
/// on a serial line, else none (a unit on its own TCP port needs none: docs/DEVICES.md).
template <typename Device>
double default_request_gap_s(const Dialect<Device>& dialect, const DeviceSpec& spec);
/// "a, b, c" of the model names.
std::string chamber_models();
std::string turntable_models();

}  // namespace station::drivers
