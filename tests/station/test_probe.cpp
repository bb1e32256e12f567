// `station probe` against a whole simulated rig (SimWorld): every device read once, failures as
// typed error lines, exit status 0 / 1 / 2.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "sim_devices/gpio_sim.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/config/config.hpp"
#include "station/daemon/rig_probe.hpp"

namespace {

using station::sim::SimWorld;

// The station's side of the world's CAN socketpair; each probe gets its own dup ("fd:N" is
// owned, and closed, by the transport that opens it).
int world_can_fd(const SimWorld& w) {
  return std::stoi(w.can_transport().substr(3));
}

std::string rig_toml(const SimWorld& w, const std::string& can_transport) {
  std::string t = fmt::format(R"([station]
name = "probe-test"
latitude_deg = 39.9
[chamber]
endpoint = "{}"
model = "generic_plc"
timeout_s = 0.2
[turntable]
endpoint = "{}"
timeout_s = 0.2
[can]
transport = "{}"
tick_timeout_ms = 200
[gpio]
interlock = "DOOR_SW"
estop = "ESTOP"
)",
                              w.chamber_endpoint(), w.turntable_endpoint(), can_transport);
  for (const auto& g : w.gyros())
    t += fmt::format("[[slot]]\nnode = {}\nserial = \"{}\"\n", g.node, g.serial);
  return t;
}

struct Probe {
  int status = -1;
  std::string out;
};

Probe probe(SimWorld& w, bool json, std::string can = {}) {
  if (can.empty()) can = fmt::format("fd:{}", dup(world_can_fd(w)));
  const auto config = station::parse_station_config(rig_toml(w, can), "probe-test.toml");
  station::RigOptions o;
  o.gpio_factory = [chips = w.gpio_chips()](const station::drivers::gpio::GpioConfig& g) {
    return std::make_unique<station::sim::GpioSimBank>(g, chips);
  };
  std::ostringstream out;
  Probe p;
  p.status = station::probe_rig(config, o, out, json);
  p.out = out.str();
  return p;
}

bool has(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

// The line of `text` that starts with `device`.
std::string line_of(const std::string& text, const std::string& device) {
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (l.rfind(device + " ", 0) == 0) return l;
  return {};
}

struct ProbeTest : testing::Test {
  ProbeTest() : world(config()) {}
  static station::sim::SimWorldConfig config() {
    station::sim::SimWorldConfig c;
    c.gyros = 2;
    c.seed = 3;
    return c;
  }
  ~ProbeTest() override { close(world_can_fd(world)); }
  SimWorld world;
};

}  // namespace

TEST_F(ProbeTest, EveryDeviceAnswersOnceAndExitIsZero) {
  const Probe p = probe(world, false);
  EXPECT_EQ(p.status, 0) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "chamber"), "ok: air 25.0 C, product 25.0 C")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "turntable"), "ok: mode off")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "can"), "2/2 boards answered")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "slot 1"), "node 1 SIM-0001")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "slot 2"), "node 2 SIM-0002")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "slot 2"), "counts delta n/a (first latch)")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "gpio interlock"), "ok: active")) << p.out;  // door closed
  EXPECT_TRUE(has(line_of(p.out, "gpio estop"), "ok: inactive")) << p.out;
  EXPECT_TRUE(has(p.out, "all devices answered")) << p.out;
}

TEST_F(ProbeTest, JsonCarriesTheValuesOfEveryDevice) {
  const Probe p = probe(world, true);
  ASSERT_EQ(p.status, 0) << p.out;
  const auto j = nlohmann::json::parse(p.out);
  EXPECT_TRUE(j["ok"].get<bool>());
  const auto& d = j["devices"];
  ASSERT_EQ(d.size(), 7u);  // chamber, turntable, can, 2 slots, interlock, estop
  EXPECT_EQ(d[0]["device"], "chamber");
  EXPECT_DOUBLE_EQ(d[0]["values"]["air_c"].get<double>(), 25.0);
  EXPECT_EQ(d[3]["values"]["serial"], "SIM-0001");
  EXPECT_EQ(d[4]["values"]["serial"], "SIM-0002");
  EXPECT_TRUE(d[3]["values"]["net_pulses"].is_null());  // first latch: no delta
  EXPECT_FALSE(d[3]["values"]["temps_c"].empty());
  for (const auto& dev : d) {
    if (dev["device"] == "gpio interlock") {
      EXPECT_TRUE(dev["values"]["active"].get<bool>());
    }
    if (dev["device"] == "gpio estop") {
      EXPECT_FALSE(dev["values"]["active"].get<bool>());
    }
  }
  EXPECT_EQ(d[6]["device"], "gpio interlock");  // lines come in the bank's (role-sorted) order
}

TEST_F(ProbeTest, ChamberTimeoutIsOneTypedLineAndTheOthersStillReport) {
  world.chamber_server().inject_timeouts(100);
  const Probe p = probe(world, false);
  EXPECT_EQ(p.status, 1) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "chamber"), "error timeout:")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "turntable"), "ok:")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "slot 1"), "ok: answered")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "slot 2"), "ok: answered")) << p.out;
  EXPECT_TRUE(has(line_of(p.out, "gpio interlock"), "ok:")) << p.out;
  EXPECT_TRUE(has(p.out, "1 of 7 failed")) << p.out;
}

TEST_F(ProbeTest, UnreachableCanBusIsADeviceFailureNotAConfigError) {
  const std::string path = testing::TempDir() + "probe-no-such.sock";
  unlink(path.c_str());
  const Probe p = probe(world, true, "unix:" + path);
  EXPECT_EQ(p.status, 1) << p.out;
  const auto j = nlohmann::json::parse(p.out);
  EXPECT_FALSE(j["ok"].get<bool>());
  EXPECT_EQ(j["devices"][0]["device"], "chamber");
  EXPECT_TRUE(j["devices"][0]["ok"].get<bool>());
  EXPECT_EQ(j["devices"][2]["device"], "can");
  EXPECT_EQ(j["devices"][2]["error"]["kind"], "disconnected");
  EXPECT_TRUE(has(j["devices"][2]["error"]["message"].get<std::string>(), path));
}

TEST(ProbeCli, BadConfigExitsTwoNamingTheFile) {
  const std::string path = testing::TempDir() + "probe-bad.toml";
  FILE* f = fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  fputs("[station]\nlatitude_deg = 123\n", f);
  fclose(f);
  const std::string cmd =
      std::string(STATION_BINARY_DIR) + "/station/station probe --config " + path + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  std::array<char, 1024> buf{};
  for (std::size_t n; (n = fread(buf.data(), 1, buf.size(), p)) > 0;) out.append(buf.data(), n);
  const int raw = pclose(p);
  EXPECT_EQ(WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, 2) << out;
  EXPECT_TRUE(has(out, "probe-bad.toml")) << out;
  EXPECT_TRUE(has(out, "latitude_deg")) << out;
}
