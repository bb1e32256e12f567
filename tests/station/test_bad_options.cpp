// Issue 19 item 13: every option of `run` is checked before the run is created. A fault command
// simrig would refuse was found only at its tick and left a 'running' run behind; `--speed nan`
// and `--seed -1` were accepted; a protocol whose first ramp would take years ran.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "station/store/store.hpp"
#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace ts = station::testing_support;

/// Runs in the database at `db` (0 when there is no database).
std::int64_t runs_in(const std::string& db) {
  if (access(db.c_str(), F_OK) != 0) return 0;
  station::Store s(db, station::OpenMode::read_only);
  auto st = s.db().prepare("SELECT count(*) FROM runs");
  return st.step() ? st.column_int(0) : -1;
}

}  // namespace

TEST(BadOptions, EachIsExit2NamingItBeforeAnyRunExists) {
  const std::string slow = ::testing::TempDir() + "slow-ramp.toml";
  std::ofstream(slow) << "name = \"slow\"\n[[step]]\ntype = \"set_temperature\"\n"
                         "setpoint_c = -40\nramp_c_per_h = 1e-300\n";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"--fault 10:explode", "--fault 10:explode: error: unknown command 'explode'"},
      {"--fault '20:board 99 reset'", "--fault 20:board 99 reset: error: node '99'"},
      // Issue 34 point 11: a time no run reaches was accepted and never fired.
      {"--fault '1e99:door open'", "--fault '1e99:door open': expected TICK:COMMAND"},
      {"--fault 'inf:door open'", "--fault 'inf:door open': expected TICK:COMMAND"},
      {"--fault '3000abc:door open'", "--fault '3000abc:door open': expected TICK:COMMAND"},
      {"--fault '99999999:door open'",
       "--fault 99999999:door open: tick 99999999 s is past the end of protocol 'paper'"},
      {"--speed nan", "--speed: 'nan' is not a finite number"},
      {"--seed -1", "--seed: '-1' is not an unsigned integer"},
      {"--protocol " + slow, slow + ":5: key 'step[0].ramp_c_per_h': 1e-300 C/h"},
  };
  for (const auto& [args, says] : cases) {
    const auto db = ts::fresh_db("bad-opt");
    const auto o = ts::station_command("run --sim --gyros 1 --db " + db + " " + args, "bad-opt");
    EXPECT_EQ(o.status, 2) << args << ": " << o.out;
    EXPECT_NE(o.out.find(says), std::string::npos) << args << ": " << o.out;
    EXPECT_EQ(runs_in(db), 0) << args << " left a run behind";
  }
}

// Issue 34 points 10 and 11: the operator, who releases and the note are text someone else reads
// (the report, the export, the fleet). A newline, 100 kB, a bidirectional override or a byte
// that is not UTF-8 is refused at the option by the one text rule (common/text_rule.hpp), before
// a run or a release exists; `--by $'\xff'` ended in json's type_error.316.
TEST(BadOptions, TextOptionsFollowTheTextRuleBeforeAnythingIsStored) {
  const std::string protocol = std::string(STATION_TEST_DATA_DIR) + "/short_cycle.toml";
  const std::vector<std::pair<std::string, std::string>> runs{
      {"--operator \"$(printf 'Ann\\nEve')\"",
       "--operator: U+000A at character 4 (byte 3) is a control character"},
      {"--operator \"$(head -c 100000 /dev/zero | tr '\\000' a)\"",
       "--operator: 100000 bytes, at most 200"},
      {"--operator \"$(printf 'Ann\\342\\200\\256')\"",
       "--operator: U+202E at character 4 (byte 3) is a bidirectional control"},
  };
  for (const auto& [args, says] : runs) {
    const auto db = ts::fresh_db("bad-text");
    const auto o = ts::station_command(
        "run --sim --gyros 1 --protocol " + protocol + " --db " + db + " " + args, "bad-text");
    EXPECT_EQ(o.status, 2) << args << ": " << o.out.substr(0, 300);
    EXPECT_NE(o.out.find(says), std::string::npos) << args << ": " << o.out.substr(0, 300);
    EXPECT_LT(o.out.size(), 400u) << "the message quotes the value";
    EXPECT_EQ(runs_in(db), 0) << args << " left a run behind";
  }
  const std::vector<std::pair<std::string, std::string>> releases{
      {"--by \"$(printf '\\377')\"", "--by: byte 0xFF at byte 0 is not UTF-8"},
      {"--by Ann --note \"$(printf 'ok\\342\\200\\256')\"",
       "--note: U+202E at character 3 (byte 2) is a bidirectional control"},
      {"--by Ann --override \"$(printf 'a\\rb')\"", "--override: U+000D at character 2"},
  };
  for (const auto& [args, says] : releases) {
    const auto db = ts::fresh_db("bad-release-text");
    const auto o = ts::station_command("release --db " + db + " --fit 1 " + args, "bad-text");
    EXPECT_EQ(o.status, 2) << args << ": " << o.out;
    EXPECT_NE(o.out.find(says), std::string::npos) << args << ": " << o.out;
    EXPECT_EQ(o.out.find("type_error"), std::string::npos) << o.out;
  }
}
