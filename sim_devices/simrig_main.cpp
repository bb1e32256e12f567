// simrig: a whole simulated rig (SimWorld) on the wall clock, for running `station` against it.
// stdout is a ready-to-use station TOML (endpoints in its leading comments); logs go to stderr.
#include <fmt/format.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "drivers/registry/dialects.hpp"
#include "sim_devices/control_socket.hpp"
#include "sim_devices/fault_commands.hpp"
#include "sim_devices/sim_world.hpp"

namespace {

namespace sim = station::sim;

volatile std::sig_atomic_t g_stop = 0;

extern "C" void on_signal(int /*sig*/) {
  g_stop = 1;
}

struct Options {
  int gyros = 4;
  std::uint64_t seed = 1;
  int chamber_port = 0;
  int turntable_port = 0;
  std::string chamber_model = "generic_plc";    // dialect the chamber speaks
  std::string turntable_model = "generic_plc";  // dialect the table speaks
  std::string acutrol_framing = "bare";         // an ACUTROL's reply framing: bare or header
  std::string can_socket = "/tmp/simrig-can.sock";
  double latitude_deg = 39.9;
  int bin_s = 0;        // the printed configuration's [station] bin_s (0: none, the paper's)
  std::string control;  // fault-injection control socket, "" = none
  std::vector<std::string> send;  // client mode: commands for a running simrig's control socket
  bool chamber_humidity = false;  // a Watlow temperature/humidity chamber (input/loop 2 %RH)
  bool chamber_cascade = false;   // an F4T with cascade control
  int chamber_unit = 1;           // the chamber's Modbus address (set at its panel)
  std::string chamber_word_order = "low_high";  // F4T floats as set at its panel
  bool chamber_gateway = false;                 // the chamber behind a TCP-to-RTU gateway
  bool acceptance_truth = false;  // issue 36: scale factor, turn-on, warm-up, misalignment
};

/// The WGS-84 rotation rate Omega = 7.292115e-5 rad/s = 15.041067 deg/h (NIMA TR8350.2, 3.2.4).
constexpr double kOmegaDph = 7.292115e-5 * 180.0 / M_PI * 3600.0;

/// Earth rate along a local-vertical input axis, deg/h: Omega * sin(lat).
double earth_rate_up_dph(double latitude_deg) {
  return kOmegaDph * std::sin(latitude_deg * M_PI / 180.0);
}

/// The Earth rate's north component, deg/h: Omega * cos(lat) (Titterton & Weston, eq. 3.41).
double earth_rate_north_dph(double latitude_deg) {
  return kOmegaDph * std::cos(latitude_deg * M_PI / 180.0);
}

/// Each gyro's acceptance truth on stderr, one line each (what `--acceptance-truth` drew).
void log_acceptance_truth(const sim::SimWorld& world) {
  for (const auto& g : world.gyros()) {
    const sim::AcceptanceTruth& a = g.acceptance;
    fmt::print(stderr,
               "simrig: node {} {} truth: sf_error_ppm {:.2f} sf_tc_ppm_per_c {:.3f} "
               "nonlinearity_ppm {:.2f} asymmetry_ppm {:.2f} full_scale_dps {} "
               "turn_on_sigma_dph {:.4f} warmup_amplitude_dph {:.4f} warmup_tau_s {:.0f} "
               "misalignment_rad {:.6f} misalignment_azimuth_deg {:.1f}\n",
               g.node, g.serial, a.sf_error_ppm, a.sf_tc_ppm_per_c, a.nonlinearity_ppm,
               a.asymmetry_ppm, a.full_scale_dps, a.turn_on_sigma_dph, a.warmup_amplitude_dph,
               a.warmup_tau_s, a.misalignment_rad, a.misalignment_azimuth_deg);
  }
}

/// Why `path` cannot be the CAN socket (empty when it can). The simulator replaces a stale
/// socket left by an earlier simrig, so anything else at the path (a regular file, a directory, a
/// symlink) is refused, never unlinked; so is a path too long for sun_path, which would be
/// truncated to another file's name.
std::string can_socket_problem(const std::string& path) {
  if (path.empty() || path.size() >= sizeof(sockaddr_un{}.sun_path)) {
    return fmt::format("--can-socket '{}': a unix socket path must be 1..{} bytes", path,
                       sizeof(sockaddr_un{}.sun_path) - 1);
  }
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return {};
    return fmt::format("--can-socket {}: {}", path, std::strerror(errno));
  }
  if (!S_ISSOCK(st.st_mode)) {
    return fmt::format("--can-socket {}: exists and is not a socket; refusing to replace it", path);
  }
  // A socket another simrig still serves is not stale: taking it over would cut that rig's
  // station off (and delete its socket at exit). Only a socket nobody answers is replaced.
  const int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
  const bool served =
      fd >= 0 && connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  if (fd >= 0) close(fd);
  if (served)
    return fmt::format("--can-socket {}: another process serves it; refusing to take it over",
                       path);
  return {};
}

void print_config(const sim::SimWorld& world, const Options& o) {
  fmt::print(
      "# simrig: simulated rig, seed {}, {} gyros, wall clock\n"
      "# chamber    {}\n# turntable  {}\n# can        {}\n"
      "# GPIO lines are simulated inside simrig only: this config has no [gpio].\n"
      "[station]\nname = \"simrig\"\nlatitude_deg = {}\nref_temp_c = 25.0\n{}\n"
      "[limits]\nmin_setpoint_c = -45.0\nmax_setpoint_c = 85.0\nmax_ramp_c_per_min = 3.0\n\n"
      "{}\n"
      "[can]\ntransport = \"{}\"\ntick_timeout_ms = 200\n",
      o.seed, o.gyros, o.chamber_model + " " + world.chamber_endpoint(),
      o.turntable_model + " " + world.turntable_endpoint(), world.can_transport(), o.latitude_deg,
      o.bin_s > 0 ? fmt::format("bin_s = {}\n", o.bin_s) : std::string(), world.devices_toml(),
      world.can_transport());
  if (!o.control.empty())
    fmt::print("# fault commands: simrig --control {} --send 'help'\n", o.control);
  for (const auto& g : world.gyros()) {
    fmt::print("\n[[slot]]\nnode = {}\nserial = \"{}\"\npulse_weight_arcsec = {}\naxis = \"{}\"\n",
               g.node, g.serial, g.pulse_weight_arcsec, g.axis);
  }
  std::fflush(stdout);
}

/// Waits up to `ms` for fault commands on the control socket (if any) and answers them.
void wait_for_commands(sim::ControlSocket* control, int ms) {
  if (control != nullptr) {
    control->service(ms);
  } else {
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));
  }
}

/// Steps the world to the wall clock every 100 ms until SIGINT/SIGTERM; accepts the station's
/// CAN connection meanwhile (accept_station polls, so a connect is served at once), and a new
/// one after a station leaves (e.g. `station probe`, then `station run`). Fault commands are
/// answered between steps, on this thread.
void serve(sim::SimWorld& world, const std::string& can, sim::ControlSocket* control) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  bool connected = false;
  fmt::print(stderr, "simrig: waiting for the station on {}\n", can);
  while (g_stop == 0) {
    if (connected && world.station_gone()) {
      connected = false;
      fmt::print(stderr, "simrig: station disconnected; waiting for the next one\n");
    }
    if (!connected) {
      connected = world.accept_station(50);
      if (connected) fmt::print(stderr, "simrig: station connected\n");
      wait_for_commands(control, connected ? 0 : 50);
    } else {
      wait_for_commands(control, 100);
    }
    world.advance_to(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  fmt::print(stderr, "simrig: stopping at t = {:.1f} s\n", world.now_s());
}

/// `simrig --control PATH --send CMD...`: prints each reply; 0 when all are "ok", else 1.
int send_commands(const Options& o) {
  if (o.control.empty()) {
    fmt::print(stderr, "simrig: --send needs --control PATH (the running simrig's socket)\n");
    return 2;
  }
  const auto replies = sim::send_control_commands(o.control, o.send);
  bool ok = true;
  for (const auto& r : replies) {
    fmt::print("{}\n", r);
    ok = ok && r.starts_with("ok");
  }
  return ok ? 0 : 1;
}

void add_options(CLI::App& app, Options& o) {
  app.add_option("--gyros", o.gyros, "simulated gyros, nodes 1..N")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  app.add_option("--seed", o.seed, "seed of coefficients and noise")->capture_default_str();
  app.add_option("--chamber", o.chamber_model,
                 "chamber dialect: " + station::drivers::chamber_models())
      ->capture_default_str();
  app.add_option("--turntable", o.turntable_model,
                 "turntable dialect: " + station::drivers::turntable_models())
      ->capture_default_str();
  app.add_option("--acutrol-framing", o.acutrol_framing,
                 "acutrol3000: replies as bare CR LF lines, or with the error/length header the "
                 "manual gives non-GPIB links (docs/DEVICES.md)")
      ->capture_default_str()
      ->check(CLI::IsMember({"bare", "header"}));
  app.add_option("--chamber-port", o.chamber_port, "chamber Modbus TCP port, 0 = ephemeral")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--turntable-port", o.turntable_port, "turntable Modbus TCP port, 0 = ephemeral")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--can-socket", o.can_socket, "unix SEQPACKET socket of the CAN bus")
      ->capture_default_str();
  app.add_option("--latitude", o.latitude_deg, "site latitude, deg (Earth rate in the gyros)")
      ->capture_default_str()
      ->check(CLI::Range(-90.0, 90.0));
  app.add_option("--bin-s", o.bin_s,
                 "[station] bin_s of the printed configuration: the bin width, s (60 for the "
                 "`demo` protocol, whose record lasts minutes; default: none printed, so the "
                 "station bins as the paper does; the station checks the value)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--chamber-humidity", o.chamber_humidity,
               "Watlow: a temperature/humidity chamber (input / loop 2 reads %RH, humidity on "
               "event 2, left on at the panel)");
  app.add_flag("--chamber-cascade", o.chamber_cascade,
               "Watlow F4T: cascade control (its part number says so; no Data Map 2)");
  app.add_option(
         "--chamber-unit", o.chamber_unit,
         "Modbus chamber: its address (unit id) set at the panel; another id is not answered")
      ->capture_default_str()
      ->check(CLI::Range(1, 247));
  app.add_option("--chamber-word-order", o.chamber_word_order,
                 "Watlow F4T: the float word order set at the panel")
      ->capture_default_str()
      ->check(CLI::IsMember({"low_high", "high_low"}));
  app.add_flag("--chamber-gateway", o.chamber_gateway,
               "Modbus chamber: a serial unit behind a TCP-to-RTU gateway (its RTU registers; "
               "exception 0x0B for another unit id)");
  app.add_flag("--acceptance-truth", o.acceptance_truth,
               "issue 36: each gyro gets a seeded scale factor error, its temperature "
               "coefficient, nonlinearity, asymmetry, turn-on bias spread, warm-up and "
               "misalignment (logged to stderr; docs/SIMRIG.md)");
  app.add_option("--control", o.control,
                 "unix stream socket for fault commands, one per line, one reply line each");
  app.add_option("--send", o.send,
                 "send these commands to a running simrig's --control socket, print the replies");
  app.footer(
      "Fault commands (--control; e.g. simrig --control /tmp/simrig.ctl --send 'door open'):\n" +
      sim::fault_command_help() + "Details: docs/SIMRIG.md");
}

sim::SimWorldConfig world_config(const Options& o) {
  sim::SimWorldConfig c;
  c.chamber_model = o.chamber_model;
  c.turntable_model = o.turntable_model;
  c.acutrol_framing = sim::acl_framing_from_name(o.acutrol_framing).value();
  c.gyros = o.gyros;
  c.seed = o.seed;
  c.chamber_port = o.chamber_port;
  c.turntable_port = o.turntable_port;
  c.can_unix_path = o.can_socket;
  c.panel.humidity = o.chamber_humidity;
  c.panel.cascade = o.chamber_cascade;
  c.panel.modbus_address = o.chamber_unit;
  c.panel.float_words = station::drivers::modbus::parse_float_word_order(o.chamber_word_order);
  c.chamber_gateway = o.chamber_gateway;
  c.earth_rate_dph = earth_rate_up_dph(o.latitude_deg);
  c.earth_rate_north_dph = earth_rate_north_dph(o.latitude_deg);
  c.acceptance_truth = o.acceptance_truth;
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulated gyro test rig: chamber, turntable, counter boards on the wall clock"};
  Options o;
  add_options(app, o);
  CLI11_PARSE(app, argc, argv);
  if (!o.send.empty()) {
    try {
      return send_commands(o);
    } catch (const std::exception& e) {
      fmt::print(stderr, "simrig: {}\n", e.what());
      return 2;
    }
  }
  if (const auto problem = can_socket_problem(o.can_socket); !problem.empty()) {
    fmt::print(stderr, "simrig: {}\n", problem);
    return 2;
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  try {
    sim::SimWorld world(world_config(o));
    std::unique_ptr<sim::ControlSocket> control;
    if (!o.control.empty()) {
      control = std::make_unique<sim::ControlSocket>(o.control, [&world](std::string_view line) {
        return sim::run_fault_command(world, line);
      });
    }
    print_config(world, o);
    if (o.acceptance_truth) log_acceptance_truth(world);
    if (control) fmt::print(stderr, "simrig: fault commands on {}\n", o.control);
    serve(world, world.can_transport(), control.get());
  } catch (const std::exception& e) {
    fmt::print(stderr, "simrig: {}\n", e.what());
    return 1;
  }
  return 0;
}
