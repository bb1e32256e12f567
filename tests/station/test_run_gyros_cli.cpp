// Issue 35 on simrig, as an operator runs it: the gyros of a run given at start by `run --config
// --slot` and by serve's API (a real HTTP client, curl), refused one line each before anything
// moves, stored with the run, kept by its resume; a configuration that names no serials.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "station/store/store.hpp"
#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace ts = station::testing_support;
using namespace std::chrono_literals;

namespace {

/// simrig's configuration without its [[slot]] serials (the rig, not the gyros) and a loose
/// lost-tick share (a killed run's down time); the path of a short protocol beside it.
struct GyroRig {
  ts::SimrigProcess sim;
  std::string dir, protocol;
  void start(const std::string& name, const std::string& http_dir = "") {
    dir = ::testing::TempDir() + name + "-" + std::to_string(getpid());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    ASSERT_TRUE(sim.start(name)) << ts::slurp(sim.err);
    std::istringstream in(ts::slurp(sim.config_path));
    std::string text, line;
    while (std::getline(in, line)) {
      if (line.rfind("serial = ", 0) == 0) continue;
      text += line + "\n";
      if (line.rfind("ref_temp_c = ", 0) == 0) text += "max_lost_share = 0.9\n";
    }
    if (!http_dir.empty()) text += "\n[http]\nprotocol_dir = \"" + dir + "\"\n";
    std::ofstream(sim.config_path) << text;
    protocol = dir + "/gyros.toml";
    std::ofstream(protocol) << "name = \"gyros\"\n[[step]]\ntype = \"record_start\"\n[[step]]\n"
                               "type = \"hold\"\nduration_s = 6\n";
  }
};

/// "serial gyro_source part" of each slot of run `run_id`, and the serials its samples carry.
struct Stored {
  std::vector<std::string> slots, sample_serials;
  int runs = 0;
};

Stored stored(const std::string& db, std::int64_t run_id = 1) {
  station::Store s(db, station::OpenMode::read_only);
  Stored out;
  auto st = s.db().prepare(
      "SELECT serial, gyro_source, coalesce(part_number, '-') FROM run_slots WHERE run_id = ? "
      "ORDER BY slot");
  st.bind(1, run_id);
  while (st.step())
    out.slots.push_back(st.column_text(0) + " " + st.column_text(1) + " " + st.column_text(2));
  auto ss = s.db().prepare("SELECT DISTINCT serial FROM samples WHERE run_id = ? ORDER BY serial");
  ss.bind(1, run_id);
  while (ss.step()) out.sample_serials.push_back(ss.column_text(0));
  auto r = s.db().prepare("SELECT count(*) FROM runs");
  if (r.step()) out.runs = static_cast<int>(r.column_int(0));
  return out;
}

std::string parts_file(const std::string& dir) {
  std::ofstream(dir + "/parts.toml") << "[part.GX-100]\nk1_dph_per_c = { max = 1.0 }\n";
  return dir + "/parts.toml";
}

int ticks(const std::string& db) {
  try {
    station::Store s(db, station::OpenMode::read_only);
    auto st = s.db().prepare("SELECT count(*) FROM samples");
    return st.step() ? static_cast<int>(st.column_int(0)) : 0;
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace

TEST(RunGyrosCli, SlotsGivenAtStartAreTheRunsAndBadOnesAreRefusedOneLineEach) {
  GyroRig rig;
  rig.start("gyros-cli");
  const std::string cfg = rig.sim.config_path, parts = parts_file(rig.dir);
  const std::string base =
      "run --config " + cfg + " --protocol " + rig.protocol + " --parts " + parts + " --db ";
  const std::vector<std::pair<std::string, std::string>> refused{
      {"--slot 1=A --slot 3=C", "station: slot 3: the configuration " + cfg + " has slots 1..2\n"},
      {"--slot 1=A --slot 2=A", "station: slot 2 (node 2): serial 'A' is on slot 1 as well\n"},
      {"--slot 1=A,GX-9 --slot 2=B",
       "station: slot 1 (node 1): part 'GX-9' is not in " + parts + " (it has: GX-100)\n"},
      {"--slot 1=A",
       "station: slot 2 (node 2): no serial (the configuration names none): give it at start, "
       "e.g. --slot 2=SERIAL\n"},
      {"",
       "station: slot 1 (node 1): no serial (the configuration names none): give it at "
       "start, e.g. --slot 1=SERIAL\nslot 2 (node 2): no serial (the configuration names "
       "none): give it at start, e.g. --slot 2=SERIAL\n"},
      {"--slot '1=A B' --slot 2=B", "station: --slot '1=A B': serial: "},
  };
  for (const auto& [args, message] : refused) {
    const auto db = ts::fresh_db("gyros-cli-refused");
    const auto o = ts::station_command(base + db + " " + args, "gyros-cli-refused");
    EXPECT_EQ(o.status, 2) << args << "\n" << o.out;
    EXPECT_NE(o.out.find(message), std::string::npos) << args << "\n" << o.out;
    EXPECT_NE(access(db.c_str(), F_OK), 0) << args << ": created " << db;
  }
  const auto db = ts::fresh_db("gyros-cli");
  const auto o =
      ts::station_command(base + db + " --slot 1=LINE-7,GX-100 --slot 2=LINE-8", "gyros-cli");
  ASSERT_EQ(o.status, 0) << o.out;
  const auto s = stored(db);
  EXPECT_EQ(s.slots, (std::vector<std::string>{"LINE-7 start GX-100", "LINE-8 start -"}));
  EXPECT_EQ(s.sample_serials, (std::vector<std::string>{"LINE-7", "LINE-8"}));
}

TEST(RunGyrosCli, ASlotWhoseBoardDoesNotAnswerIsRefusedNamingItsGyro) {
  GyroRig rig;
  rig.start("gyros-cli-node");
  std::ofstream(rig.sim.config_path, std::ios::app) << "\n[[slot]]\nnode = 9\n";
  const auto db = ts::fresh_db("gyros-cli-node");
  const auto o =
      ts::station_command("run --config " + rig.sim.config_path + " --protocol " + rig.protocol +
                              " --db " + db + " --slot 1=A --slot 2=B --slot 3=NODE9-GYRO",
                          "gyros-cli-node");
  EXPECT_EQ(o.status, 2) << o.out;
  EXPECT_NE(o.out.find("node 9 NODE9-GYRO"), std::string::npos) << o.out;
  EXPECT_NE(access(db.c_str(), F_OK), 0) << "the database was created";
}

TEST(RunGyrosCli, AResumeKeepsItsSerialsAndRefusesOthers) {
  GyroRig rig;
  rig.start("gyros-resume");
  const auto db = ts::fresh_db("gyros-resume");
  const std::vector<std::string> run{ts::kStationBin, "run",        "--config", rig.sim.config_path,
                                     "--protocol",    rig.protocol, "--db",     db};
  auto first = run;
  first.insert(first.end(), {"--slot", "1=KEEP-1", "--slot", "2=KEEP-2"});
  const pid_t pid = ts::spawn_process(first, db + ".1.out", db + ".1.err");
  ASSERT_TRUE(ts::wait_until([&] { return ticks(db) >= 4; }, 20s)) << ts::slurp(db + ".1.err");
  kill(pid, SIGKILL);
  ts::wait_bounded(pid, 5s);
  const auto other = ts::station_command(
      fmt::format("run --config {} --protocol {} --db {} --slot 1=KEEP-1 --slot 2=OTHER",
                  rig.sim.config_path, rig.protocol, db),
      "gyros-resume-other");
  EXPECT_EQ(other.status, 2) << other.out;
  EXPECT_NE(other.out.find("run 1 was started with other gyros: slot 2 serial 'KEEP-2' -> 'OTHER'; "
                           "start a new run with --new"),
            std::string::npos)
      << other.out;
  const pid_t again = ts::spawn_process(run, db + ".2.out", db + ".2.err");
  const int st = ts::wait_bounded(again, 60s);
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << ts::slurp(db + ".2.err");
  const auto s = stored(db);
  EXPECT_EQ(s.runs, 1);
  EXPECT_EQ(s.slots, (std::vector<std::string>{"KEEP-1 start -", "KEEP-2 start -"}));
  EXPECT_EQ(s.sample_serials, (std::vector<std::string>{"KEEP-1", "KEEP-2"}));
  EXPECT_NE(ts::slurp(db + ".2.err").find("resum"), std::string::npos) << ts::slurp(db + ".2.err");
}

namespace {

/// POST `body` to serve's /api/runs with curl: "CODE BODY".
std::string post_run(const std::string& port, const std::string& token, const std::string& body,
                     const std::string& tag) {
  const pid_t curl = ts::spawn_process(
      {"/usr/bin/curl", "-s", "-o", tag + ".body", "-w", "%{http_code}", "-X", "POST", "-H",
       "Authorization: Bearer " + token, "-H", "Content-Type: application/json", "-d", body,
       "http://127.0.0.1:" + port + "/api/runs"},
      tag + ".code", tag + ".err");
  ts::wait_bounded(curl, 20s);
  return ts::slurp(tag + ".code") + " " + ts::slurp(tag + ".body");
}

}  // namespace

TEST(RunGyrosApi, TheStartBodyGivesTheGyrosAndABadOneIs400NamingTheField) {
  GyroRig rig;
  rig.start("gyros-api", "http");
  const auto db = ts::fresh_db("gyros-api");
  const pid_t service =
      ts::spawn_process({ts::kStationBin, "serve", "--config", rig.sim.config_path, "--db", db,
                         "--http", "127.0.0.1:0"},
                        db + ".out", db + ".err");
  std::string port;
  ASSERT_TRUE(ts::wait_until(
      [&] {
        const std::string text = ts::slurp(db + ".out");
        const auto at = text.find("127.0.0.1:");
        if (at == std::string::npos) return false;
        port = text.substr(at + 10, text.find_first_not_of("0123456789", at + 10) - at - 10);
        return !port.empty();
      },
      20s))
      << ts::slurp(db + ".err");
  std::string token = ts::slurp(db + ".token");
  token = token.substr(0, token.find_first_of("\r\n"));
  const std::vector<std::pair<std::string, std::string>> bad{
      {R"({"protocol":"gyros","slots":{"1":{"serial":"A B"}}})", "field 'slots/1/serial': "},
      {R"({"protocol":"gyros","slots":{"one":{"serial":"A"}}})", "field 'slots/one': "},
      {R"({"protocol":"gyros","slots":{"1":{"serial":"A","colour":"red"}}})",
       "field 'slots/1/colour': unknown"},
      {R"({"protocol":"gyros","slots":{"1":"A"}})", "field 'slots/1': expected an object"},
      {R"({"protocol":"gyros","slots":{"1":{"part":"GX-100"}}})",
       "field 'slots/1/serial': required"},
      {R"({"protocol":"gyros","slots":["A"]})", "field 'slots': expected an object"},
      {R"({"protocol":"gyros","slots":{"1":{"serial":"A"},"3":{"serial":"C"}}})",
       "slot 3: the configuration"},
      {R"({"protocol":"gyros","slots":{"1":{"serial":"A"}}})", "slot 2 (node 2): no serial"},
      {R"({"protocol":"gyros","slots":{"1":{"serial":"A"},"2":{"serial":"A"}}})",
       "slot 2 (node 2): serial 'A' is on slot 1 as well"},
      {R"({"protocol":"gyros","slots":{"1":{"serial":"A","part":"GX-100"},"2":{"serial":"B"}}})",
       "slot 1 (node 1): part 'GX-100' but no part file"},
  };
  for (const auto& [body, error] : bad) {
    const auto got = post_run(port, token, body, db + ".bad");
    EXPECT_EQ(got.substr(0, 4), "400 ") << body << "\n" << got;
    EXPECT_NE(got.find(error), std::string::npos) << body << "\n" << got;
  }
  const auto ok = post_run(
      port, token,
      R"({"protocol":"gyros","operator":"t","slots":{"1":{"serial":"API-1"},"2":{"serial":"API-2"}}})",
      db + ".ok");
  EXPECT_EQ(ok.substr(0, 4), "202 ") << ok;
  EXPECT_TRUE(ts::wait_until(
      [&] {
        try {
          station::Store s(db, station::OpenMode::read_only);
          const auto run = s.find_run(1);
          return run && run->state != station::RunState::running;
        } catch (const std::exception&) {
          return false;
        }
      },
      60s));
  kill(service, SIGTERM);
  ts::wait_bounded(service, 20s);
  const auto s = stored(db);
  EXPECT_EQ(s.slots, (std::vector<std::string>{"API-1 start -", "API-2 start -"}));
  EXPECT_EQ(s.sample_serials, (std::vector<std::string>{"API-1", "API-2"}));
}
