// Issue 19 items 1-3: one database and one device, whatever their names. The database lock is
// taken on the file itself (a hard link, a symlink, `./` and `..` are the same lock); a device lock
// on what its endpoint resolves to (`localhost` is 127.0.0.1); a SQLite file that is not a
// station's is refused before any pragma writes to it.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "station/daemon/device_identity.hpp"
#include "station/store/store.hpp"
#include "tests/station/rig_process.hpp"

namespace {

namespace fs = std::filesystem;
namespace ts = station::testing_support;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / (name + "-" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d / "sub");
  return d;
}

std::set<std::string> names_in(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t samples_of(const std::string& db) {
  try {
    station::Store s(db, station::OpenMode::read_only);
    return s.samples(1, "SIM-0001", false).size();
  } catch (const std::exception&) {  // not created yet
    return 0;
  }
}

struct Exit {
  int status = -1;
  std::string err;
};

/// Runs `station ARGS...` to its end (bounded: a refusal must come at once).
Exit station_exit(std::vector<std::string> args, const std::string& log) {
  args.insert(args.begin(), ts::kStationBin);
  const pid_t pid = ts::spawn_process(args, log + ".out", log + ".err");
  const int status = ts::wait_bounded(pid, std::chrono::seconds(5));
  if (status == -1) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    return {-1, "did not exit within 5 s: " + ts::slurp(log + ".err")};
  }
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ts::slurp(log + ".err")};
}

void make_foreign_sqlite(const std::string& path, int user_version) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  const std::string sql =
      "create table customer_orders(id integer primary key, customer text, total real);"
      "insert into customer_orders values (1, 'ACME', 12.5);"
      "pragma user_version = " +
      std::to_string(user_version) + ";";
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
}

}  // namespace

// Before: the lock was DB.lock beside the path string; through a hard link a second daemon
// "resumed" run 1 beside the first and its checkpoint wiped committed samples.
TEST(SameFile, ASecondDaemonThroughAnyNameOfTheDatabaseExits2AndTouchesNothing) {
  const fs::path dir = fresh_dir("same-db");
  const std::string db = (dir / "a.db").string();
  const pid_t first = ts::spawn_process(
      {ts::kStationBin, "run", "--sim", "--speed", "50", "--gyros", "1", "--db", db},
      db + ".first.out", db + ".first.err");
  ASSERT_TRUE(ts::wait_until([&] { return samples_of(db) >= 20; }, std::chrono::seconds(20)))
      << ts::slurp(db + ".first.err");
  fs::create_hard_link(dir / "a.db", dir / "hard.db");
  fs::create_symlink("a.db", dir / "sym.db");
  const std::set<std::string> before = names_in(dir);
  const std::vector<std::string> names{(dir / "hard.db").string(), (dir / "sym.db").string(),
                                       (dir / "." / "a.db").string(),
                                       (dir / "sub" / ".." / "a.db").string()};
  for (const auto& name : names) {
    const Exit e = station_exit({"run", "--sim", "--speed", "50", "--gyros", "1", "--db", name},
                                (dir / "second").string());
    EXPECT_EQ(e.status, 2) << name << ": " << e.err;
    EXPECT_NE(e.err.find("pid " + std::to_string(first)), std::string::npos) << name << e.err;
    EXPECT_EQ(e.err.find("resum"), std::string::npos) << name << e.err;
    auto now = names_in(dir);
    now.erase("second.out");
    now.erase("second.err");
    EXPECT_EQ(now, before) << name << ": a file appeared or vanished";
  }
  // The first daemon is untouched: alive and still committing.
  const std::size_t had = samples_of(db);
  EXPECT_TRUE(ts::wait_until([&] { return samples_of(db) >= had + 20; }, std::chrono::seconds(10)));
  EXPECT_EQ(waitpid(first, nullptr, WNOHANG), 0) << "the first daemon died";
  kill(first, SIGTERM);
  ts::wait_bounded(first, std::chrono::seconds(10));
}

// Before: the device lock was keyed on the endpoint string; `tcp://localhost:P` drove rig A's
// chamber while A ran.
TEST(SameFile, EndpointsAreKeyedOnWhatTheyResolveTo) {
  const auto v4 = station::device_identities("tcp://127.0.0.1:5020");
  ASSERT_EQ(v4, std::vector<std::string>{"tcp://127.0.0.1:5020"});
  const auto local = station::device_identities("tcp://LocalHost:5020");
  EXPECT_NE(std::find(local.begin(), local.end(), "tcp://127.0.0.1:5020"), local.end())
      << ::testing::PrintToString(local);
  EXPECT_EQ(station::device_identities("tcp://[::ffff:127.0.0.1]:5020"), v4);
  EXPECT_NE(station::device_identities("tcp://127.0.0.1:5021"), v4);
  // A serial line and a socket through a symlink are the file they point to.
  const fs::path dir = fs::canonical(fresh_dir("same-dev"));
  std::ofstream(dir / "ttyX").flush();
  fs::create_symlink(dir / "ttyX", dir / "gyro-chamber");
  EXPECT_EQ(station::device_identities("rtu:" + (dir / "gyro-chamber").string() + "?baud=9600"),
            station::device_identities("rtu:" + (dir / "sub" / ".." / "ttyX").string()));
  EXPECT_EQ(station::device_identities("rtu:" + (dir / "ttyX").string()),
            std::vector<std::string>{"rtu:" + (dir / "ttyX").string()});
}

TEST(SameFile, ASecondConfigurationNamingTheChamberAsLocalhostExits2) {
  ts::SimrigProcess rig;
  ASSERT_TRUE(rig.start("same-dev")) << ts::slurp(rig.err);
  std::string text = ts::slurp(rig.config_path);
  ASSERT_NE(text.find("127.0.0.1"), std::string::npos) << text;
  const std::string hold = std::string(STATION_TEST_DATA_DIR) + "/hold_150.toml";
  const fs::path dir = fresh_dir("same-dev-run");
  const std::string db_a = (dir / "a.db").string(), db_b = (dir / "b.db").string();
  const pid_t first = ts::spawn_process(
      {ts::kStationBin, "run", "--config", rig.config_path, "--protocol", hold, "--db", db_a},
      db_a + ".out", db_a + ".err");
  ASSERT_TRUE(ts::wait_until([&] { return samples_of(db_a) >= 2; }, std::chrono::seconds(15)))
      << ts::slurp(db_a + ".err");
  // Rig B is a second simrig (its own turntable and CAN bus) whose configuration names rig A's
  // chamber as `localhost`: no endpoint string of B equals one of A's; the chamber resolves to
  // the same address and port.
  const auto chamber_endpoint_at = [](const std::string& config) {
    return config.find("endpoint = \"", config.find("[chamber]")) + 12;
  };
  const auto at_a = chamber_endpoint_at(text);
  const std::string chamber_a = text.substr(at_a, text.find('"', at_a) - at_a);
  ASSERT_EQ(chamber_a.rfind("tcp://127.0.0.1:", 0), 0u) << text;
  ts::SimrigProcess rig_b;
  ASSERT_TRUE(rig_b.start("same-dev-b")) << ts::slurp(rig_b.err);
  text = ts::slurp(rig_b.config_path);
  const auto at_b = chamber_endpoint_at(text);
  text.replace(at_b, text.find('"', at_b) - at_b,
               "tcp://localhost:" + chamber_a.substr(chamber_a.rfind(':') + 1));
  const std::string config_b = (dir / "b.toml").string();
  std::ofstream(config_b) << text;
  const Exit e = station_exit({"run", "--config", config_b, "--protocol", hold, "--db", db_b},
                              (dir / "b").string());
  EXPECT_EQ(e.status, 2) << e.err;
  EXPECT_NE(e.err.find("pid " + std::to_string(first)), std::string::npos) << e.err;
  EXPECT_EQ(samples_of(db_b), 0u);
  EXPECT_EQ(waitpid(first, nullptr, WNOHANG), 0) << "the first daemon died";
  kill(first, SIGTERM);
  ts::wait_bounded(first, std::chrono::seconds(10));
}

// Before: at user_version 0 the station added its tables and a run and switched the file to WAL;
// at user_version 3 it refused, after switching WAL on and writing a .bak.
TEST(SameFile, AForeignSqliteFileIsRefusedBeforeAnyPragmaWrites) {
  for (const int version : {0, 3}) {
    const fs::path dir = fresh_dir("foreign-" + std::to_string(version));
    const std::string db = (dir / "orders.db").string();
    make_foreign_sqlite(db, version);
    const std::string before = bytes_of(db);
    const auto names = names_in(dir);
    for (const std::vector<std::string>& cmd :
         {std::vector<std::string>{"run", "--sim", "--gyros", "1", "--db", db},
          std::vector<std::string>{"fit", "--all", "--db", db}}) {
      const Exit e = station_exit(cmd, (dir.parent_path() / "foreign-out").string());
      EXPECT_EQ(e.status, 2) << cmd[0] << " v" << version << ": " << e.err;
      EXPECT_NE(e.err.find(db), std::string::npos) << e.err;
      EXPECT_NE(e.err.find("not a station database"), std::string::npos) << e.err;
      EXPECT_EQ(bytes_of(db), before) << cmd[0] << " v" << version << " wrote to the file";
      EXPECT_EQ(names_in(dir), names) << cmd[0] << " v" << version << ": WAL, journal or .bak";
    }
  }
}
