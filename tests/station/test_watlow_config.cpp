// Issue 33 points 4 and 5, the configuration's side: the product input is an explicit choice a
// dialect must have, Data Map 2's input 2 is humidity, limits and the humidity event are checked;
// each error names the key and its line.
#include <gtest/gtest.h>

#include <string>

#include "station/common/input_error.hpp"
#include "station/config/config.hpp"

namespace {

std::string error_of(const std::string& chamber) {
  const std::string text = "[station]\nlatitude_deg = 39.9\n[chamber]\n" + chamber +
                           "[can]\ntransport = \"unix:/tmp/can.sock\"\n[[slot]]\nnode = 1\n"
                           "serial = \"A\"\n";
  try {
    (void)station::parse_station_config(text, "rig.toml");
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

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
