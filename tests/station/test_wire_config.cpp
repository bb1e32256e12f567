// Issue 33 point 6, the station's side: the [chamber] keys of the link (timing from the dialect,
// request_gap_s, word_order, gateway, a serial broadcast unit_id refused) and what `station
// probe` shows of them against a simulated F4T.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <sstream>
#include <string>

#include "sim_devices/gpio_sim.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/config/config.hpp"
#include "station/daemon/rig_probe.hpp"

namespace {

using station::sim::SimWorld;

const std::string kHead = "[station]\nlatitude_deg = 39.9\n";
const std::string kTail =
    "[can]\ntransport = \"unix:/tmp/can.sock\"\n[[slot]]\nnode = 1\nserial = \"A\"\n";

std::string rig(const std::string& chamber) {
  return kHead + "[chamber]\n" + chamber + kTail;
}

station::StationConfig parse(const std::string& chamber) {
  return station::parse_station_config(rig(chamber), "rig.toml");
}

std::string error_of(const std::string& chamber) {
  try {
    (void)parse(chamber);
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(LinkConfig, TimingIsTheDialectsUnlessGiven) {
  const std::string f4t = "model = \"watlow_f4t\"\n";
  const auto tcp = parse(f4t + "endpoint = \"tcp://10.0.0.5:502\"\n");
  EXPECT_DOUBLE_EQ(tcp.chamber.timeout_s, 0.5);
  EXPECT_DOUBLE_EQ(tcp.chamber.request_gap_s, 0.0);
  const auto rtu = parse(f4t + "endpoint = \"rtu:/dev/ttyUSB0?baud=9600\"\n");
  EXPECT_DOUBLE_EQ(rtu.chamber.request_gap_s, 0.030);  // CCL modbus.py:375
  const auto gw = parse(f4t + "endpoint = \"tcp://10.0.0.5:502\"\ngateway = true\n");
  EXPECT_TRUE(gw.chamber.gateway);
  EXPECT_DOUBLE_EQ(gw.chamber.request_gap_s, 0.030);
  const auto given = parse(f4t +
                           "endpoint = \"rtu:/dev/ttyUSB0\"\nrequest_gap_s = 0.05\n"
                           "timeout_s = 0.3\n");
  EXPECT_DOUBLE_EQ(given.chamber.request_gap_s, 0.05);
  EXPECT_DOUBLE_EQ(given.chamber.timeout_s, 0.3);
  const auto none = parse(f4t + "endpoint = \"rtu:/dev/ttyUSB0\"\nrequest_gap_s = 0\n");
  EXPECT_DOUBLE_EQ(none.chamber.request_gap_s, 0.0);
}

TEST(LinkConfig, WordOrderIsTheUnitsPanelSpelling) {
  const std::string f4t = "model = \"watlow_f4t\"\nendpoint = \"tcp://10.0.0.5:502\"\n";
  EXPECT_FALSE(parse(f4t).chamber.word_order);
  const auto high = parse(f4t + "word_order = \"high_low\"\n");
  ASSERT_TRUE(high.chamber.word_order);
  EXPECT_EQ(*high.chamber.word_order, station::drivers::modbus::WordOrder::abcd);
  EXPECT_TRUE(has(error_of(f4t + "word_order = \"sideways\"\n"),
                  "key 'chamber.word_order': invalid word order 'sideways'"))
      << error_of(f4t + "word_order = \"sideways\"\n");
  const std::string f4 = "model = \"watlow_f4\"\nendpoint = \"tcp://10.0.0.5:502\"\n";
  EXPECT_TRUE(has(error_of(f4 + "word_order = \"high_low\"\n"),
                  "key 'chamber.word_order': word_order: model 'watlow_f4' has no float"))
      << error_of(f4 + "word_order = \"high_low\"\n");
}

TEST(LinkConfig, KeysThatCannotApplyAreRefusedNamingTheKey) {
  const std::string p300 = "model = \"espec_p300\"\nendpoint = \"tcp://10.0.0.5:10001\"\n";
  for (const char* key : {"request_gap_s = 0.1", "gateway = true", "word_order = \"low_high\""}) {
    const std::string e = error_of(p300 + key + "\n");
    const std::string name = std::string(key).substr(0, std::string(key).find(' '));
    EXPECT_TRUE(has(e, "key 'chamber." + name + "'")) << e;
    EXPECT_TRUE(has(e, "speaks ASCII")) << e;
  }
  const std::string rtu = "model = \"watlow_f4t\"\nendpoint = \"rtu:/dev/ttyUSB0\"\n";
  EXPECT_TRUE(has(error_of(rtu + "gateway = true\n"), "key 'chamber.gateway'"))
      << error_of(rtu + "gateway = true\n");
  EXPECT_TRUE(has(error_of(rtu + "unit_id = 0\n"),
                  "key 'chamber.unit_id': unit_id 0 is the "
                  "broadcast address"))
      << error_of(rtu + "unit_id = 0\n");
  EXPECT_TRUE(has(error_of(rtu + "request_gap_s = 2\n"), "key 'chamber.request_gap_s'"));
}

namespace {

struct ProbeLine {
  int status = -1;
  std::string chamber;  ///< the chamber's line of the text report
};

// `station probe` of a simulated world: its own [chamber] table (devices_toml: the panel's unit
// id and word order, the gateway), or with `bare` only the model and the endpoint.
ProbeLine probe_chamber(const station::sim::SimWorldConfig& wc, bool bare = false) {
  SimWorld w(wc);
  const int fd = dup(std::stoi(w.can_transport().substr(3)));
  std::string t = kHead + (bare ? fmt::format("[chamber]\nmodel = \"{}\"\nendpoint = \"{}\"\n",
                                              wc.chamber_model, w.chamber_endpoint())
                                : w.devices_toml());
  t += fmt::format("[can]\ntransport = \"fd:{}\"\ntick_timeout_ms = 200\n", fd);
  for (const auto& g : w.gyros())
    t += fmt::format("[[slot]]\nnode = {}\nserial = \"{}\"\n", g.node, g.serial);
  std::ostringstream out;
  ProbeLine p;
  p.status = station::probe_rig(station::parse_station_config(t, "probe.toml"),
                                station::RigOptions{}, out, false);
  close(std::stoi(w.can_transport().substr(3)));
  std::istringstream in(out.str());
  for (std::string l; std::getline(in, l);)
    if (l.rfind("chamber ", 0) == 0) p.chamber = l;
  if (p.chamber.empty()) p.chamber = out.str();
  return p;
}

station::sim::SimWorldConfig f4t_world() {
  station::sim::SimWorldConfig c;
  c.gyros = 1;
  c.chamber_model = "watlow_f4t";
  return c;
}

// Issue 33 points 4 and 5: the product input is an explicit choice a dialect must have, Data
// Map 2's input 2 is humidity, limits and the humidity event are checked.
const std::string kF4t = "model = \"watlow_f4t\"\nendpoint = \"tcp://127.0.0.1:502\"\n";
const std::string kMap2 = "model = \"watlow_f4t_map2\"\nendpoint = \"tcp://127.0.0.1:502\"\n";

TEST(WatlowConfig, TheProductInputIsADialectsChoice) {
  EXPECT_EQ(error_of(kF4t + "product_input = 2\n"), "");
  EXPECT_EQ(error_of(kF4t + "product_input = 0\n"), "");
  const auto one = error_of(kF4t + "product_input = 1\n");
  EXPECT_TRUE(has(one, "rig.toml:6: key 'chamber.product_input'")) << one;
  EXPECT_TRUE(has(one, "input 1 is the air")) << one;
  const auto map2 = error_of(kMap2 + "product_input = 2\n");
  EXPECT_TRUE(has(map2, "key 'chamber.product_input'")) << map2;
  EXPECT_TRUE(has(map2, "input 2 is humidity")) << map2;
  const auto plc = error_of("endpoint = \"tcp://127.0.0.1:502\"\nproduct_input = 2\n");
  EXPECT_TRUE(has(plc, "model 'generic_plc' has no input to choose")) << plc;
}

TEST(WatlowConfig, LimitsAndHumidityEventAreChecked) {
  EXPECT_EQ(error_of(kMap2 + "setpoint_low_c = -40\nsetpoint_high_c = 80\nhumidity_event = 3\n"),
            "");
  const auto limits = error_of(kMap2 + "setpoint_low_c = 80\nsetpoint_high_c = -40\n");
  EXPECT_TRUE(has(limits, "key 'chamber.setpoint_low_c'")) << limits;
  const auto event = error_of(kF4t + "humidity_event = 9\n");
  EXPECT_TRUE(has(event, "key 'chamber.humidity_event'")) << event;
}

}  // namespace

TEST(LinkProbe, ShowsTheWordOrderTheUnitsRegisterAndTheLink) {
  const std::string plain = probe_chamber(f4t_world()).chamber;
  EXPECT_TRUE(has(plain, "ok: air 25.0 C")) << plain;
  EXPECT_TRUE(has(plain, "floats low word first (word_order = \"low_high\")")) << plain;
  EXPECT_TRUE(has(plain, "units register 6730 (the TCP port's)")) << plain;
  EXPECT_TRUE(has(plain, "link: unit 1, timeout 0.50 s, request gap 0.000 s")) << plain;

  auto c = f4t_world();
  c.panel.float_words = station::drivers::modbus::WordOrder::abcd;
  c.panel.modbus_address = 7;
  c.chamber_gateway = true;
  const std::string gw = probe_chamber(c).chamber;  // its TOML: high_low, unit 7, gateway
  EXPECT_TRUE(has(gw, "ok: air 25.0 C")) << gw;
  EXPECT_TRUE(has(gw, "floats high word first (word_order = \"high_low\")")) << gw;
  EXPECT_TRUE(has(gw, "units register 14080 (the serial port's)")) << gw;
  EXPECT_TRUE(has(gw, "link: unit 7 behind a gateway, timeout 0.50 s, request gap 0.030 s")) << gw;
}

TEST(LinkProbe, AWordOrderOrUnitIdThatIsNotTheUnitsIsRefusedWithOneLine) {
  auto c = f4t_world();
  c.panel.float_words = station::drivers::modbus::WordOrder::abcd;
  const ProbeLine order = probe_chamber(c, true);  // the station reads low word first
  EXPECT_EQ(order.status, 1);
  EXPECT_TRUE(has(order.chamber, "error protocol:")) << order.chamber;
  EXPECT_TRUE(has(order.chamber, "set word_order = \"high_low\"")) << order.chamber;

  c = f4t_world();
  c.panel.modbus_address = 7;
  const ProbeLine unit = probe_chamber(c, true);  // the station asks unit 1
  EXPECT_EQ(unit.status, 1);
  EXPECT_TRUE(has(unit.chamber, "error timeout:")) << unit.chamber;
  EXPECT_TRUE(has(unit.chamber, "unit 1 has not answered")) << unit.chamber;
}
