// `station sync` as a process: killed (SIGKILL) in the middle of forwarding, then run again: the
// second run sends exactly what the server did not commit — nothing twice, nothing lost.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <thread>

#include "station/store/store.hpp"
#include "tests/fleet/fleet_fixture.hpp"

extern char** environ;

namespace {

namespace fleet = station::fleet;
using station::testing_support::FleetTest;

const std::string kStation = std::string(STATION_BINARY_DIR) + "/station/station";

std::int64_t local_count(const std::string& db, const std::string& table) {
  station::Database d(db, station::OpenMode::read_only);
  auto st = d.prepare("SELECT count(*) FROM " + table);
  st.step();
  return st.column_int(0);
}

std::int64_t server_count(const std::string& table) {
  fleet::PgConnection pg(FleetTest::target());
  return pg.exec("SELECT count(*) FROM " + table).integer(0, 0);
}

std::string capture(const std::string& cmd, int& rc) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  rc = pclose(p);
  return out;
}

class FleetSync : public FleetTest {};

TEST_F(FleetSync, KilledMidBatchThenRerunSendsNothingTwice) {
  const auto db = simulated_station("fleet_killed", 2, 21);
  {
    station::Store migrate(db);  // the outbox exists before the process starts
  }
  const std::int64_t total = local_count(db, "samples") + local_count(db, "events");
  const std::string url = target().url;
  std::vector<std::string> args = {kStation, "sync",      "--db",         db,   "--pg",
                                   url,      "--samples", "--batch-rows", "500"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, kStation.c_str(), nullptr, nullptr, argv.data(), environ), 0);
  // Kill it once some batches have landed, long before the end (batches of 500 rows).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (server_count("samples") < 2'000 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "sync finished before it could be killed";
  const std::int64_t landed = server_count("samples") + server_count("events");
  ASSERT_LT(landed, total) << "everything had landed: the kill came too late to test anything";

  int rc = 0;
  const auto out =
      capture(kStation + " sync --json --samples --db " + db + " --pg '" + url + "'", rc);
  ASSERT_EQ(rc, 0) << out;
  const auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j["rows_appended"].get<std::int64_t>(), total - landed)
      << "the rerun sent rows the server already had, or missed some";
  EXPECT_EQ(server_count("samples") + server_count("events"), total);
  EXPECT_EQ(j["pending_items"].get<std::int64_t>(), 0);
}

TEST_F(FleetSync, AnUnreachableServerExitsOneWithOneLineAndKeepsTheBacklog) {
  const auto db = simulated_station("fleet_unreachable", 1, 22);
  int rc = 0;
  const auto out = capture(kStation + " sync --db " + db +
                               " --pg 'postgresql:///postgres?host=/nonexistent&user=x' 2>&1",
                           rc);
  EXPECT_EQ(WEXITSTATUS(rc), 1) << out;
  EXPECT_NE(out.find("station: error: PostgreSQL"), std::string::npos) << out;
  fleet::Forwarder f(db, target(), {});
  EXPECT_GT(f.backlog().runs, 0);
  const auto password =
      capture(kStation + " sync --db " + db + " --pg 'postgresql://u:secret@localhost/x' 2>&1", rc);
  EXPECT_EQ(WEXITSTATUS(rc), 2) << password;
  EXPECT_NE(password.find("password"), std::string::npos) << password;
}

}  // namespace
