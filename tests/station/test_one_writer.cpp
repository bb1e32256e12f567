// Issue 34 points 8 and 9: one lock for every writer, whatever name it uses, and read commands
// that stay read-only.
// 8: a writing command takes the daemon's lock on the file (refused naming the daemon), and a
//    database is never opened by another name than the one its write-ahead log sits beside.
// 9: export, history and report read a database on a read-only mount, and leave no -wal or -shm
//    beside a database on a writable one.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "station/store/store.hpp"
#include "tests/station/release_fixture.hpp"
#include "tests/station/rig_process.hpp"

namespace {

namespace fs = std::filesystem;
namespace ts = station::testing_support;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / (name + "-" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
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

/// `sql` on `db` through a connection that is closed without a checkpoint: its writes stay in
/// DB-wal, as a writer killed before its checkpoint leaves them.
void leave_in_wal(const std::string& db, const std::string& sql) {
  sqlite3* c = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &c), SQLITE_OK);
  ASSERT_EQ(sqlite3_db_config(c, SQLITE_DBCONFIG_NO_CKPT_ON_CLOSE, 1, nullptr), SQLITE_OK);
  EXPECT_EQ(sqlite3_exec(c, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK)
      << sqlite3_errmsg(c);
  sqlite3_close(c);
}

std::int64_t count_rows(const std::string& db, const std::string& table) {
  sqlite3* c = nullptr;
  EXPECT_EQ(sqlite3_open_v2(db.c_str(), &c, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  std::int64_t n = -1;
  if (sqlite3_prepare_v2(c, ("SELECT count(*) FROM " + table).c_str(), -1, &st, nullptr) ==
          SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW)
    n = sqlite3_column_int64(st, 0);
  sqlite3_finalize(st);
  sqlite3_close(c);
  return n;
}

/// The three read commands on `db`, the report written to `out`.
std::vector<std::string> read_commands(const std::string& db, const std::string& out) {
  return {"export --serial SIM-0001 --db " + db, "history --serial SIM-0001 --db " + db,
          "report --run 1 --out " + out + " --db " + db};
}

}  // namespace

// Before: `station fit` through a hard link during a run exited 0 (or 1), its fits lost, and left
// hardlink.db-wal and -shm; through the daemon's own name it wrote beside the daemon.
TEST(OneWriter, AWritingCommandDuringARunIsRefusedNamingTheDaemonWhateverTheName) {
  const fs::path dir = fresh_dir("one-writer");
  const std::string db = (dir / "a.db").string();
  const pid_t daemon = ts::spawn_process(
      {ts::kStationBin, "run", "--sim", "--speed", "50", "--gyros", "1", "--db", db},
      db + ".daemon.out", db + ".daemon.err");
  ASSERT_TRUE(ts::wait_until([&] { return samples_of(db) >= 20; }, std::chrono::seconds(20)))
      << ts::slurp(db + ".daemon.err");
  fs::create_hard_link(dir / "a.db", dir / "hard.db");
  const std::string daemon_text = "station run (pid " + std::to_string(daemon) + ")";
  for (const std::string name : {"a.db", "hard.db"}) {
    const std::string path = (dir / name).string();
    const auto before = names_in(dir);
    for (const std::string cmd : {"fit --all --db " + path, "release --fit 1 --by T --db " + path,
                                  "verify --serial SIM-0001 --run 1 --db " + path}) {
      const auto o = ts::station_command(cmd, "one-writer");
      EXPECT_EQ(o.status, 2) << cmd << ": " << o.out;
      EXPECT_NE(o.out.find(daemon_text), std::string::npos) << cmd << ": " << o.out;
      EXPECT_EQ(names_in(dir), before) << cmd << ": a -wal or -shm appeared";
    }
  }
  // A reader through the link reads nothing stale: it is told the writer's name.
  const auto o = ts::station_command("history --serial SIM-0001 --db " + (dir / "hard.db").string(),
                                     "one-writer");
  EXPECT_EQ(o.status, 2) << o.out;
  EXPECT_NE(o.out.find(daemon_text), std::string::npos) << o.out;
  EXPECT_NE(o.out.find(db), std::string::npos) << o.out;
  EXPECT_FALSE(fs::exists(dir / "hard.db-wal"));
  EXPECT_FALSE(fs::exists(dir / "hard.db-shm"));
  EXPECT_EQ(waitpid(daemon, nullptr, WNOHANG), 0) << "the daemon died";
  kill(daemon, SIGTERM);
  ts::wait_bounded(daemon, std::chrono::seconds(10));
}

// Before: with a killed writer's commits still in a.db-wal, `fit` through hard.db read the file
// without them, wrote its own hard.db-wal and checkpointed over a.db's pages.
TEST(OneWriter, ADatabaseWhoseLogSitsBesideAnotherNameIsRefusedByEveryCommand) {
  const fs::path dir = fresh_dir("other-name");
  const std::string db = (dir / "a.db").string(), hard = (dir / "hard.db").string();
  { station::Store s(db); }
  leave_in_wal(db, "CREATE TABLE kept(x); INSERT INTO kept VALUES (1);");
  ASSERT_GT(fs::file_size(db + "-wal"), 32u) << "the commit is not in the WAL";
  fs::create_hard_link(db, hard);
  const std::string wal_before = bytes_of(db + "-wal"), db_before = bytes_of(db);
  const fs::path out = fresh_dir("other-name-report");
  auto commands = read_commands(hard, out.string());
  commands.push_back("fit --all --db " + hard);
  commands.push_back("run --sim --gyros 1 --db " + hard);
  for (const auto& cmd : commands) {
    const auto o = ts::station_command(cmd, "other-name");
    EXPECT_EQ(o.status, 2) << cmd << ": " << o.out;
    EXPECT_NE(o.out.find(db + "-wal"), std::string::npos) << cmd << ": " << o.out;
    EXPECT_NE(o.out.find("open it as " + db), std::string::npos) << cmd << ": " << o.out;
    EXPECT_FALSE(fs::exists(hard + "-wal")) << cmd;
    EXPECT_FALSE(fs::exists(hard + "-shm")) << cmd;
    EXPECT_EQ(bytes_of(db), db_before) << cmd << " wrote to the file";
    EXPECT_EQ(bytes_of(db + "-wal"), wal_before) << cmd << " touched the log";
  }
  EXPECT_EQ(count_rows(db, "kept"), 1);  // through its own name the commit is there
}

// Before: a hard link in another directory went unseen: a log a killed writer left beside one
// name was missed by a writer through the other, which checkpointed over it.
TEST(OneWriter, AWriterRefusesAFileWithANameInAnotherDirectory) {
  const fs::path dir = fresh_dir("far-name"), far = fresh_dir("far-name-link");
  const std::string db = (dir / "a.db").string(), link = (far / "b.db").string();
  { station::Store s(db); }
  fs::create_hard_link(db, link);
  const auto names = names_in(far);
  const auto o = ts::station_command("fit --all --db " + link, "far-name");
  EXPECT_EQ(o.status, 2) << o.out;
  EXPECT_NE(o.out.find("has 2 names (hard links) and only 1 are here"), std::string::npos) << o.out;
  EXPECT_EQ(names_in(far), names) << "a -wal or -shm appeared beside the link";
  // A read through it is harmless (it writes nothing) and leaves nothing.
  EXPECT_EQ(ts::station_command("history --serial X --db " + link, "far-name").out.find("names"),
            std::string::npos);
  EXPECT_EQ(names_in(far), names);
}

// Before: export, history and report each left a.db-wal and a.db-shm beside the database.
TEST(ReadOnlyCommands, LeaveNoFileBesideTheDatabase) {
  const auto calibrated = ts::calibrated_db("read-only-files", 1);
  const fs::path out = fresh_dir("read-only-report");
  for (const auto& cmd : read_commands(calibrated.path, out.string())) {
    const auto o = ts::station_command(cmd, "read-only-files");
    EXPECT_EQ(o.status, 0) << cmd << ": " << o.out;
    EXPECT_FALSE(fs::exists(calibrated.path + "-wal")) << cmd << " left a -wal";
    EXPECT_FALSE(fs::exists(calibrated.path + "-shm")) << cmd << " left a -shm";
  }
}

// Before: on a read-only mount each exited 2, "not a readable station database" (a WAL database
// cannot be read without its -shm, which cannot be created there).
TEST(ReadOnlyCommands, ReadADatabaseOnAReadOnlyMount) {
  if (std::system("unshare -m true >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "unshare -m is not permitted here: a read-only bind mount cannot be made";
  const auto calibrated = ts::calibrated_db("read-only-mount", 1);
  const fs::path dir = fresh_dir("read-only-mount");
  const std::string db = (dir / "station.db").string();
  fs::copy_file(calibrated.path, db);
  const fs::path out = fresh_dir("read-only-mount-report");
  const auto before = names_in(dir);
  for (const auto& cmd : read_commands(db, out.string())) {
    // The mount exists only in the command's own mount namespace (unshare -m).
    // The mount exists only in the command's own mount namespace (unshare -m); the command runs
    // only once writing there fails.
    const std::string shell = "unshare -m sh -c 'mount --bind -o ro " + dir.string() + " " +
                              dir.string() + " || exit 90; if touch " + db +
                              " 2>/dev/null; then exit 91; fi; exec " + ts::kStationBin + " " +
                              cmd + "'";
    const std::string log = (out / "cmd.out").string();
    const int rc = std::system((shell + " >" + log + " 2>&1").c_str());
    EXPECT_EQ(WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, 0) << cmd << ": " << ts::slurp(log);
    EXPECT_EQ(names_in(dir), before) << cmd;
  }
  // A writer there says it cannot write, not that the file is unreadable.
  const std::string log = (out / "fit.out").string();
  const int rc = std::system(("unshare -m sh -c 'mount --bind -o ro " + dir.string() + " " +
                              dir.string() + " || exit 90; exec " + ts::kStationBin +
                              " fit --all --db " + db + "' >" + log + " 2>&1")
                                 .c_str());
  EXPECT_EQ(WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, 2) << ts::slurp(log);
  EXPECT_NE(ts::slurp(log).find("a writing command cannot write"), std::string::npos)
      << ts::slurp(log);
}
