// A whole simulated rig: chamber and turntable Modbus servers, N simulated RLG counter boards on
// one CAN bus, and a GPIO line bank, advanced together in lockstep on simulated time. Used by
// `station run --sim`, by the daemon tests and (on the wall clock) by `simrig`.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/counter_board_sim.hpp"
#include "sim_devices/faces/sim_dialects.hpp"
#include "sim_devices/gpio_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace station::sim {

/// Which kind of gyro the simulated slots hold.
///  - station: distinct coefficients over a wide range (|k1| 2..5e-3, |k0| 0.01..0.04), a strong
///    thermal effect against the noise, and a physical gradient across the gyro (sim_thermal:
///    ~0.25 C at 10 C/h, ~1.5 C at 60 C/h);
///  - paper: the thermal effect and noise in the proportions of the paper's gyros: on the paper's
///    cycle the std of the bias after compensation is ~0.13 of the std before (docs/SIMRIG.md).
enum class GyroPreset { station, paper };
/// "station" / "paper"; empty when unknown.
std::optional<GyroPreset> gyro_preset_from_name(std::string_view name);

/// What to simulate.
struct SimWorldConfig {
  int gyros = 4;           ///< simulated RLGs, nodes 1..gyros (at most 16)
  std::uint64_t seed = 1;  ///< drives coefficients and every noise source
  /// 0: the seed's own noise. N > 0: the same gyros (coefficients) with independent gyro noise,
  /// as a second run of the same gyros on another day (run --sim --verify).
  std::uint64_t noise_run = 0;
  GyroPreset preset = GyroPreset::station;  ///< coefficients of the simulated gyros
  /// The Earth rate's vertical component W sin(lat), deg/h, from the caller: along each gyro's
  /// input axis when it is mounted as before issue 36 (vertical, no misalignment).
  double earth_rate_dph = 0;
  /// Its north component W cos(lat), deg/h, from the caller: what a misaligned or horizontal
  /// input axis sees of it as the table turns (0: that part of the projection is missing).
  double earth_rate_north_dph = 0;
  double initial_c = 25.0;           ///< chamber and gyros at t = 0, deg C
  double pulse_weight_arcsec = 1.5;  ///< every gyro's pulse weight
  std::string can_unix_path;         ///< empty: socketpair (in-process); else listen on this path
  int chamber_port = 0;              ///< chamber Modbus TCP port on 127.0.0.1, 0 = ephemeral
  int turntable_port = 0;            ///< turntable Modbus TCP port on 127.0.0.1, 0 = ephemeral
  ChamberSimConfig chamber;          ///< chamber model
  /// Dialects the chamber and table are served in (drivers/registry model names).
  std::string chamber_model = "generic_plc";
  std::string turntable_model = "generic_plc";
  WatlowPanel panel;  ///< a simulated Watlow's decimals, units and run event
  AclFraming acutrol_framing = AclFraming::bare;  ///< how a simulated ACUTROL frames replies
  /// The chamber is a serial unit behind a TCP-to-RTU gateway (serve_chamber).
  bool chamber_gateway = false;
  TurntableSimConfig table;  ///< the turntable's limits
  /// Issue 36: every gyro gets its own seeded acceptance truth (sim_acceptance_truth: scale
  /// factor, turn-on, warm-up, misalignment), and the gyros' power follows their relays (as
  /// relay_power). Off: the gyros of before, bit for bit.
  bool acceptance_truth = false;
  /// Gyro n is powered while its relay line GYRO_PWRn is high, once a bank has claimed that line
  /// as an output; a line nobody claimed is a slot without a relay: always powered. Off: always
  /// powered, whatever the lines do (the default: a safe hold that drops the relays leaves the
  /// gyros' data as it was before issue 36).
  bool relay_power = false;
  /// A gyro's truth by node, over acceptance_truth's (or the all-zero default).
  std::map<std::uint8_t, AcceptanceTruth> acceptance_by_node;
  /// Gyro n's input axis horizontal at this heading (deg clockwise from north at table angle 0):
  /// its truth mounted so (mounted_horizontal); a node not here keeps its axis (up).
  std::map<std::uint8_t, double> horizontal_heading_by_node;
};

/// One simulated gyro as the station will see it.
struct SimGyro {
  std::uint8_t node = 1;
  std::string serial;
  double pulse_weight_arcsec = 1.5;
  TrueCoefficients truth;
  AcceptanceTruth acceptance;  ///< its acceptance-test truth (all zero unless configured)
  /// Its [[slot]] axis as a station configuration writes it: "up", or "heading:DEG" for a
  /// horizontal input axis (the nominal heading of its truth).
  std::string axis = "up";
};

/// The simulated rig. Construction starts the Modbus servers (loopback, configured ports) and
/// creates the CAN bus; it is the hardware, so it does I/O.
class SimWorld {
 public:
  explicit SimWorld(const SimWorldConfig& config);
  ~SimWorld();
  SimWorld(const SimWorld&) = delete;
  SimWorld& operator=(const SimWorld&) = delete;

  /// tcp://127.0.0.1:PORT of the chamber and turntable servers.
  std::string chamber_endpoint() const { return chamber_.server->endpoint(); }
  std::string turntable_endpoint() const { return table_.server->endpoint(); }
  /// The [chamber] and [turntable] tables of a station config for this world: model, endpoint.
  std::string devices_toml() const;
  /// CAN transport spec for the station: "fd:N" (socketpair end) or "unix:PATH".
  std::string can_transport() const { return can_transport_; }
  /// With can_unix_path: blocks up to timeout_ms for the station to connect, then serves; after
  /// a station closed its end, the next call accepts a new one (fresh boards at now_s()).
  /// Returns false on timeout. (With a socketpair the bus is serving from construction.)
  bool accept_station(int timeout_ms);
  /// True when the station connected over can_unix_path has closed its end since.
  bool station_gone() const { return listen_fd_ >= 0 && bus_ && bus_->peer_closed(); }
  /// GPIO line names: DOOR_SW, ESTOP, TOWER_G/A/R, GYRO_PWR1..N.
  std::shared_ptr<GpioSimChips> gpio_chips() const { return gpio_; }

  /// Injected faults that stay until changed (sim_devices/fault_commands.hpp drives them).
  /// The door: GPIO DOOR_SW (high = closed) and the chamber's door-open alarm bit.
  void set_door_open(bool open);
  /// The e-stop: GPIO ESTOP (high = pressed) and the turntable's interlock (the e-stop chain
  /// disables the drive). simrig's config has no [gpio]: a station on simrig sees the table bit.
  void set_estop(bool pressed);
  bool door_open() const { return door_open_; }
  bool estop_pressed() const { return estop_; }
  /// CAN fault probabilities per frame, for this and every later station connection.
  void set_can_fault_rates(const BusFaultRates& rates);
  const BusFaultRates& can_fault_rates() const { return can_rates_; }
  /// Gyro `node`'s temperature channel reads the sensor's sentinel (or recovers); kept across
  /// station connections. Throws std::invalid_argument for an unknown node or channel.
  void set_gyro_temp_failed(std::uint8_t node, int channel, bool failed);
  /// Board `node` stops or resumes answering SYNCs; kept across station connections.
  void set_board_answering(std::uint8_t node, bool answering);
  /// Ends every injected fault: door closed, e-stop released, alarms, Modbus and CAN faults.
  void clear_faults();

  /// Advances chamber, table and every gyro to t_s (air temperature feeds the gyros).
  void advance_to(double t_s);
  /// Returns once the device servers have applied the link faults due now (SimServer::settle):
  /// after advance_to and the fault commands of a tick, on the simulated clock.
  void settle() const {
    chamber_.server->settle();
    table_.server->settle();
  }
  double now_s() const { return now_s_; }

  const std::vector<SimGyro>& gyros() const { return gyros_; }
  /// Gyro `node`'s acceptance truth, for "figure vs truth"; throws std::invalid_argument for an
  /// unknown node.
  const AcceptanceTruth& acceptance_truth(std::uint8_t node) const;
  /// Gyro `node`'s power-ups so far on the current bus (times on the world's clock, each with its
  /// turn-on bias); empty before a station connected over can_unix_path.
  std::vector<PowerUp> power_ups(std::uint8_t node);
  /// Whether gyro `node` is powered now (relay_power: its relay line; else always).
  bool gyro_powered(std::uint8_t node) const;
  ChamberSim& chamber() { return *chamber_sim_; }
  TurntableSim& turntable() { return *table_sim_; }
  SimServer& chamber_server() { return *chamber_.server; }
  SimServer& turntable_server() { return *table_.server; }
  CounterBoardBus* bus() { return bus_.get(); }

 private:
  void add_boards();
  void check_node(std::uint8_t node) const;
  bool relay_power() const { return config_.relay_power || config_.acceptance_truth; }

  SimWorldConfig config_;
  std::vector<SimGyro> gyros_;
  std::unique_ptr<ChamberSim> chamber_sim_;
  std::unique_ptr<TurntableSim> table_sim_;
  // The world's time, read by the servers' threads (link-fault durations): declared before them.
  std::atomic<double> now_s_ = 0;
  ServedDevice chamber_, table_;  // faces and servers (destroyed before the models)
  std::unique_ptr<CounterBoardBus> bus_;
  std::shared_ptr<GpioSimChips> gpio_;
  std::string can_transport_;
  int listen_fd_ = -1;
  bool door_open_ = false, estop_ = false;
  BusFaultRates can_rates_;
  std::map<std::uint8_t, int> failed_temp_;  // node -> channel
  std::set<std::uint8_t> silent_boards_;
};

/// Distinct, realistic true coefficients for gyro `index` of a world seeded with `seed`
/// (k2 = 0 so the paper's model B0 + k1 dT + k0 gradT is exact).
TrueCoefficients sim_coefficients(std::uint64_t seed, int index,
                                  GyroPreset preset = GyroPreset::station);
/// The thermal lags of a preset's gyros (initial_c left at its default; the world sets it).
ThermalParams sim_thermal(GyroPreset preset);
/// Serial number of simulated gyro `index`: SIM-0001... (station), PAP-0001... (paper).
std::string sim_serial(GyroPreset preset, int index);

}  // namespace station::sim
