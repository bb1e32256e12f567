// `station run --sim`: the embedded default. Simulated gyros with distinct known coefficients
// on the simulators of sim_devices, reached through their real transports (Modbus TCP on
// loopback, CAN on a socketpair), the protocol on the simulated clock, and a true-vs-fitted table.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace station::sim {
class SimWorld;
}

namespace station {

struct SequencerOptions;

/// Options of a simulated run.
struct SimRunOptions {
  int gyros = 4;
  std::uint64_t seed = 1;
  std::uint64_t noise_run = 0;  ///< sim::SimWorldConfig::noise_run (same gyros, new noise)
  std::string chamber_model = "generic_plc";    ///< dialect the simulated chamber speaks
  std::string turntable_model = "generic_plc";  ///< dialect the simulated table speaks
  std::string acutrol_framing = "bare";  ///< a simulated ACUTROL's replies: "bare" or "header"
  std::string gyro_preset = "station";   ///< sim::GyroPreset by name: "station" or "paper"
  double latitude_deg = 39.9;
  /// Slot i's input axis (a [[slot]] axis: up, north, south, east, west or heading:DEG), the
  /// slots past the list up; the simulated gyro is mounted so (SimWorldConfig::
  /// horizontal_heading_by_node). An axis neither up nor horizontal is an InputError.
  std::vector<std::string> axes;
  std::string protocol = "paper";   ///< shipped name or file
  std::string db_path;              ///< empty: station-sim.db in the current directory
  bool fresh = false;               ///< ignore an unfinished run in the database
  bool progress = true;             ///< progress lines on stderr
  bool wall_clock = false;          ///< run at 1 Hz on CLOCK_MONOTONIC instead of simulated time
  double speed = 0;                 ///< simulated s per wall s (0: as fast as possible)
  std::string record_can_path;      ///< write every CAN frame in candump format here (empty: no)
  std::string record_dir;           ///< record the session in this directory (empty: no)
  std::string parts_path;           ///< part file: every simulated gyro is judged (empty: no)
  std::string part_number;          ///< their part (empty: the file's first in sort order)
  std::string on_foreign_setpoint;  ///< [chamber] on_foreign_setpoint (empty: the default)
  double turntable_timeout_s = 0;   ///< [turntable] timeout_s (0: the dialect's)
  /// Faults injected into the simulated rig: at tick t_s (after the world advanced to it), the
  /// simrig control command (docs/SIMRIG.md), e.g. {3000, "door open"}. In time order.
  std::vector<std::pair<double, std::string>> faults;
  const std::atomic<bool>* stop = nullptr;
  /// Adds hooks to the sequencer's options before the run (the live hub: live::attach).
  std::function<void(SequencerOptions&)> extend;
  /// Test hook: called with each tick's time and the world, after it advanced (fault injection).
  std::function<void(double t_s, sim::SimWorld& world)> on_world_tick;
};

/// The part the simulated gyros are given: empty without a part file; throws InputError for a
/// bad part file, a part it lacks, or --part without a file. Called before anything moves.
std::optional<std::string> sim_part_number(const SimRunOptions& options);

/// Runs the simulated rig to the end of the protocol (or a resumed one to its end) and returns
/// the report: {"run_id","sim_s","wall_s","gyros":[{serial,true,fitted,std_errors,std_*}]}.
nlohmann::json run_simulated(const SimRunOptions& options);

/// `run --sim --verify`: the run above, then each gyro's fit released when its verdict allows
/// (by "station run --sim --verify"), then a second run of the same gyros with independent
/// noise, on which each released calibration is verified (station/release/verification.hpp).
/// Returns the second run's report with "calibration_run" (the first's), "releases" and
/// "verifications".
nlohmann::json run_simulated_with_verification(const SimRunOptions& options);

}  // namespace station
