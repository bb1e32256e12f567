// The station configuration file (TOML): devices, limits, slots. Validated completely before
// anything moves; every error names the file, the line and the key. Schema:
// schemas/station_config.schema.json.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "compensation/binning.hpp"
#include "compensation/earth_rate.hpp"
#include "drivers/gpio/gpio_bank.hpp"
#include "drivers/modbus/map_overrides.hpp"
#include "drivers/modbus/readback.hpp"
#include "drivers/registry/dialects.hpp"
#include "station/common/input_error.hpp"
#include "station/config/fleet_config.hpp"

namespace station {

/// A chamber or turntable: its model (a dialect of drivers/registry/dialects.hpp), endpoint
/// and the knobs of its dialect ([chamber] / [turntable]; `preset` is the old name of `model`).
using DeviceConfig = drivers::DeviceSpec;

/// One gyro position on the rig.
struct SlotConfig {
  int node = 1;  ///< CAN node id of its counter board, 1..16
  /// The gyro's serial number: a default for runs that give none for this slot (empty: each
  /// run must give one, daemon/run_gyros.hpp).
  std::string serial;
  double pulse_weight_arcsec = 1.5;  ///< angle per net pulse, arcsec
  std::string axis = "up";    ///< input axis: up, down, north, south, east, west, heading:DEG
  compensation::EnuAxis enu;  ///< the axis as a unit vector
  std::string relay;          ///< GPIO line powering this gyro (optional)
  std::string part;           ///< part number, a key of the part file (empty: none); a default
  std::size_t part_line = 0;  ///< line of the `part` key, for messages naming it
  bool gyro_given = false;    ///< serial (and part) given with the run, not the file's default
};

/// The station's hard limits, enforced by the safety layer whatever a protocol asks.
struct LimitsConfig {
  double min_setpoint_c = -45.0;
  double max_setpoint_c = 85.0;
  double max_ramp_c_per_min = 3.0;
  /// Air temperature this far beyond the setpoint limits is a fault (safe hold), °C.
  double air_margin_c = 5.0;
};

/// Everything in a station configuration file.
/// `station serve`'s HTTP service ([http]); paths resolved against the configuration's folder.
struct HttpConfig {
  std::string listen = "127.0.0.1:8080";  ///< HOST:PORT (--http overrides)
  std::string token_file;                 ///< empty: DB.token
  std::string protocol_dir;  ///< NAME.toml files the API may start, besides the shipped ones
};

struct StationConfig {
  std::string path;  ///< file it came from
  std::string text;  ///< its full text (snapshot stored with each run)
  std::string name = "station";
  double latitude_deg = 0;                  ///< geodetic latitude of the site, deg
  double ref_temp_c = 25.0;                 ///< T_ref of the model
  double bin_s = compensation::kPaperBinS;  ///< bin width, s
  /// Largest share of a slot's record-window ticks that may lack a rate (link outages) before
  /// the run ends 'incomplete', 0..1.
  double max_lost_share = 0.05;
  /// Part file ([station] parts, station/parts/part_file.hpp) resolved against the folder of
  /// this file; empty when the key is absent.
  std::string parts_path;
  DeviceConfig chamber;
  /// [chamber] on_foreign_setpoint: "restore" (default: the station's setpoint is written again)
  /// or "hold" (a safe hold until the chamber reads the station's setpoint again), when the
  /// chamber's setpoint reads other than the station commanded (station/daemon/setpoint_watch).
  std::string on_foreign_setpoint = "restore";
  std::optional<DeviceConfig> turntable;
  std::string can_transport;  ///< socketcan:can0 | unix:PATH | fd:N
  int can_tick_timeout_ms = 200;
  /// GPIO lines by role ([gpio] and the slots' relays); unset when the rig has none.
  std::optional<drivers::gpio::GpioConfig> gpio;
  LimitsConfig limits;
  std::vector<SlotConfig> slots;
  HttpConfig http;
  /// [fleet]: the central PostgreSQL this station forwards to; unset when it forwards nowhere.
  std::optional<FleetConfig> fleet;
};

/// Reads and validates a configuration file; throws InputError ("FILE:LINE: key 'k': ...").
StationConfig load_station_config(const std::string& path);
/// The same from text labelled as `path`.
StationConfig parse_station_config(const std::string& text, const std::string& path);

}  // namespace station
