// Issue 33, point 1 at the station: [turntable] framing is checked like every key, and a run on
// an ACUTROL that refuses every command for a while (simrig's `table refuse`) ends in one clear
// event naming the refusal and a safe hold, then completes, in either reply framing.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "drivers/registry/dialects.hpp"
#include "station/config/config.hpp"
#include "station/sim/sim_run.hpp"
#include "station/store/store.hpp"
#include "tests/station/sim_options.hpp"
#include "tests/station/temp_db.hpp"

namespace {

const std::string kRig = R"([station]
latitude_deg = 39.9
[chamber]
endpoint = "tcp://127.0.0.1:502"
[can]
transport = "unix:/tmp/can.sock"
[[slot]]
node = 1
serial = "A"
[turntable]
endpoint = "tcp://192.168.53.1:9878"
)";

std::string error_of(const std::string& text) {
  try {
    station::parse_station_config(text, "rig.toml");
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

TEST(AcutrolConfig, FramingIsOneOfTheDialectsAndNamedWhenWrong) {
  const std::string acutrol = kRig + "model = \"acutrol3000\"\n";
  for (const char* f : {"auto", "bare", "header"}) {
    const auto c = station::parse_station_config(acutrol + "framing = \"" + f + "\"\n", "rig.toml");
    EXPECT_EQ(c.turntable->framing, f);
  }
  EXPECT_EQ(station::parse_station_config(acutrol, "rig.toml").turntable->framing, "");
  const std::string wrong = error_of(acutrol + "framing = \"crlf\"\n");
  EXPECT_NE(wrong.find("key 'turntable.framing': framing 'crlf': model 'acutrol3000' takes one "
                       "of auto,bare,header"),
            std::string::npos)
      << wrong;
  const std::string plc = error_of(kRig + "model = \"generic_plc\"\nframing = \"bare\"\n");
  EXPECT_NE(plc.find("key 'turntable.framing': framing: model 'generic_plc' has no reply framing"),
            std::string::npos)
      << plc;
}

// The schema's framing names are the registry's, as its model names are (DialectNames).
TEST(AcutrolConfig, TheSchemaTakesExactlyTheRegistrysFramings) {
  std::set<std::string> registry;
  for (const auto& d : station::drivers::turntable_dialects()) {
    std::string_view f = d.framings;
    while (!f.empty()) {
      const auto comma = f.find(',');
      registry.emplace(f.substr(0, comma));
      f = comma == std::string_view::npos ? "" : f.substr(comma + 1);
    }
  }
  std::ifstream in(std::string(STATION_SOURCE_DIR) + "/schemas/station_config.schema.json");
  const auto e =
      nlohmann::json::parse(in)["$defs"]["modbus_device"]["properties"]["framing"]["enum"];
  EXPECT_EQ(std::set<std::string>(e.begin(), e.end()), registry);
}

TEST(AcutrolRuns, ARefusingTableEndsInOneEventAndASafeHold) {
  for (const char* framing : {"bare", "header"}) {
    const auto db = station::testing_support::fresh_db(std::string("acutrol_refuse_") + framing);
    auto o = station::testing_support::short_cycle_run(db, 1);
    o.turntable_model = "acutrol3000";
    o.acutrol_framing = framing;
    o.faults = {{1500, "table refuse 8"}};
    const auto r = station::run_simulated(o);
    ASSERT_EQ(r["state"], "completed") << framing << " " << r.dump();
    station::Store store(db);
    int starts = 0, holds = 0, ends = 0;
    for (const auto& e : store.event_rows(r["run_id"].get<std::int64_t>())) {
      if (e.t_s < 1500 || e.t_s > 1530) continue;
      if (e.kind == "outage_start" && e.source == "turntable") {
        ++starts;
        EXPECT_NE(e.message.find("':Read:Position? 1;Rate? 1' refused by the unit"),
                  std::string::npos)
            << e.message;
        EXPECT_NE(e.message.find("ILLEGAL CMD"), std::string::npos) << e.message;
      }
      holds += e.kind == "safe_hold";
      ends += e.kind == "outage" && e.source == "turntable";
    }
    EXPECT_EQ(starts, 1) << framing;
    EXPECT_EQ(holds, 1) << framing << ": the table's interlock unread for 5 ticks holds the rig";
    EXPECT_EQ(ends, 1) << framing;
  }
}

}  // namespace
