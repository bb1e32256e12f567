// A dialect is one row of the registry: the names the configuration's schema accepts, the ones
// the simulator serves and the error texts all come from that row (drivers/registry/dialects.cpp).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "drivers/registry/dialects.hpp"
#include "sim_devices/faces/sim_dialects.hpp"

namespace {

using station::drivers::chamber_dialects;
using station::drivers::turntable_dialects;

template <typename Rows>
void add_names(const Rows& rows, std::set<std::string>& out) {
  for (const auto& d : rows) {
    out.emplace(d.model);
    std::string_view a = d.aliases;
    while (!a.empty()) {
      const auto comma = a.find(',');
      out.emplace(a.substr(0, comma));
      a = comma == std::string_view::npos ? "" : a.substr(comma + 1);
    }
  }
}

std::set<std::string> schema_enum(const char* key) {
  std::ifstream in(std::string(STATION_SOURCE_DIR) + "/schemas/station_config.schema.json");
  const auto schema = nlohmann::json::parse(in);
  const auto& e = schema.at("$defs").at("modbus_device").at("properties").at(key).at("enum");
  return {e.begin(), e.end()};
}

TEST(DialectNames, TheSchemaAcceptsExactlyTheRegistrysNamesAndAliases) {
  std::set<std::string> names;
  add_names(chamber_dialects(), names);
  add_names(turntable_dialects(), names);
  EXPECT_EQ(schema_enum("model"), names);
  EXPECT_EQ(schema_enum("preset"), names);
}

TEST(DialectNames, AnAliasFindsItsRowAndAnUnknownNameListsTheRows) {
  EXPECT_EQ(station::drivers::chamber_dialect("f4t").model, "watlow_f4t");
  EXPECT_EQ(station::drivers::turntable_dialect("default").model, "generic_plc");
  try {
    (void)station::drivers::chamber_dialect("acme");
    FAIL() << "acme accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(station::drivers::chamber_models()), std::string::npos)
        << e.what();
  }
}

TEST(DialectNames, OnlyRowsWithEventOutputsTakeARunEvent) {
  for (const auto& d : chamber_dialects()) {
    station::drivers::DeviceSpec spec;
    spec.name = "chamber";
    spec.model = std::string(d.model);
    spec.endpoint = d.transport == station::drivers::Transport::modbus ? "tcp://127.0.0.1:1502"
                                                                       : "tcp://127.0.0.1:10001";
    spec.run_event = 2;
    if (d.event_outputs)
      EXPECT_NO_THROW(station::drivers::validate(d, spec)) << d.model;
    else
      EXPECT_THROW(station::drivers::validate(d, spec), std::invalid_argument) << d.model;
  }
}

TEST(DialectNames, TheSimulatorWritesRunEventOnlyForRowsWithEventOutputs) {
  station::sim::WatlowPanel panel;
  panel.run_event = 3;
  for (const auto& d : chamber_dialects()) {
    const auto toml = station::sim::device_toml("chamber", d.model, "tcp://127.0.0.1:1", &panel);
    EXPECT_EQ(toml.find("run_event = 3") != std::string::npos, d.event_outputs) << toml;
  }
}

}  // namespace
