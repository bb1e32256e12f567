// Issue 34 points 8-9, hostile review: the writer's lock and an immutable reader under races.
// - A file a writer created and then failed to lock (another process locked it first) stays
//   where it is, with that process's data; refusals do not pile up descriptors.
// - An `immutable=1` reader (no writer about, a directory it cannot write) whose file a writer
//   starts changing after the choice refuses its result instead of reporting it.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "station/common/database_lock.hpp"
#include "station/common/input_error.hpp"
#include "station/store/store.hpp"

namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / (name + "-" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  fs::permissions(d, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                         fs::perms::others_read | fs::perms::others_exec);
  return d;
}

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t open_descriptors() {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

// The other process of the race: opens the new file and locks it before its creator does (a
// separate open file description: flock(2) conflicts between descriptions, in one process too).
int other_fd = -1;
void other_writer_locks_first(const std::string& path) {
  other_fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(other_fd, 0);
  ASSERT_EQ(::flock(other_fd, LOCK_EX | LOCK_NB), 0);
  ASSERT_EQ(::write(other_fd, "B's run", 7), 7);
}

TEST(DatabaseRaces, ACreatorThatLosesTheLockLeavesTheFileToItsHolder) {
  const std::string db = (fresh_dir("lost-lock") / "race.db").string();
  station::database_lock_hooks::after_create = other_writer_locks_first;
  EXPECT_THROW(station::DatabaseHold::writer(db, true), station::InputError);
  station::database_lock_hooks::after_create = nullptr;
  EXPECT_TRUE(fs::exists(db)) << "the holder's file was unlinked under it";
  EXPECT_EQ(bytes_of(db), "B's run");
  ::close(other_fd);
}

TEST(DatabaseRaces, RefusalsOpenNoDescriptorEach) {
  const std::string db = (fresh_dir("refusals") / "held.db").string();
  std::ofstream(db) << "x";
  const std::size_t base = open_descriptors();
  const int holder = ::open(db.c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_EQ(::flock(holder, LOCK_EX | LOCK_NB), 0);
  const std::size_t before = open_descriptors();
  for (int i = 0; i < 50; ++i)
    EXPECT_THROW(station::DatabaseHold::writer(db, false), station::InputError);
  EXPECT_LE(open_descriptors(), before + 1) << "one descriptor per file at most";
  ::close(holder);
  {
    const auto hold = station::DatabaseHold::writer(db, false);  // the kept descriptor locks it
    EXPECT_TRUE(station::DatabaseHold::held_here(db));
  }
  EXPECT_EQ(open_descriptors(), base) << "the hold's end closes the kept descriptor";
}

enum ReaderVerdict { kUnchanged = 10, kRefused = 11, kOther = 12 };

// A child reads `db` as a user who cannot write its directory (immutable=1), waits at `go` until
// the parent has done its part, then checks its result: kUnchanged or kRefused.
pid_t immutable_reader(const std::string& db, int ready, int go) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(kOther);
  try {
    station::Store store(db, station::OpenMode::read_only);
    (void)store.find_run(1);
    char c = 'r';
    if (::write(ready, &c, 1) != 1 || ::read(go, &c, 1) != 1) ::_exit(kOther);
    store.db().check_unchanged();
    ::_exit(kUnchanged);
  } catch (const station::InputError& e) {
    ::_exit(std::string(e.what()).find("changed while it was read") != std::string::npos ? kRefused
                                                                                         : kOther);
  } catch (...) {
    ::_exit(kOther);
  }
}

int read_while(const fs::path& dir, bool write_meanwhile) {
  const std::string db = (dir / "station.db").string();
  { station::Store make(db, station::OpenMode::create); }
  fs::permissions(dir, fs::perms::owner_write, fs::perm_options::remove);  // 0555 for non-root
  int ready[2], go[2];
  EXPECT_EQ(::pipe(ready), 0);
  EXPECT_EQ(::pipe(go), 0);
  const pid_t child = immutable_reader(db, ready[1], go[0]);
  char c = 0;
  EXPECT_EQ(::read(ready[0], &c, 1), 1);
  fs::permissions(dir, fs::perms::owner_write, fs::perm_options::add);
  if (write_meanwhile) {  // a daemon starting a run: writes, checkpoints and closes
    station::Database w(db, station::OpenMode::existing);
    w.exec("CREATE TABLE scratch(x); INSERT INTO scratch VALUES (zeroblob(100000));");
  }
  EXPECT_EQ(::write(go[1], "g", 1), 1);
  int status = 0;
  EXPECT_EQ(::waitpid(child, &status, 0), child);
  for (const int fd : {ready[0], ready[1], go[0], go[1]}) ::close(fd);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(DatabaseRaces, AnImmutableReaderRefusesAFileAWriterChangedMeanwhile) {
  EXPECT_EQ(read_while(fresh_dir("immutable-changed"), true), kRefused);
}

TEST(DatabaseRaces, AnImmutableReaderOfAnUnchangedFileSucceeds) {
  EXPECT_EQ(read_while(fresh_dir("immutable-quiet"), false), kUnchanged);
}

}  // namespace
