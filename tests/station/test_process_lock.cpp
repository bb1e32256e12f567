// ProcessLock: one holder at a time, and a lock file another user made (as /run/lock holds them
// between the service's user, operators and root) can still be locked.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "station/common/input_error.hpp"
#include "station/common/process_lock.hpp"

namespace {

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() /
                 ("lock-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace

TEST(ProcessLock, OneHolderAtATimeAndTheRefusalNamesIt) {
  const auto file = (fresh_dir("one") / "x.lock").string();
  auto held = station::ProcessLock::acquire(file, "device X");
  try {
    (void)station::ProcessLock::acquire(file, "device X");
    ADD_FAILURE() << "a second holder was let in";
  } catch (const station::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("device X is in use by another station process (pid " +
                                         std::to_string(::getpid())),
              std::string::npos)
        << e.what();
  }
}

TEST(ProcessLock, ANewLockFileIsReadableByAllWhateverTheUmask) {
  const auto file = (fresh_dir("umask") / "x.lock").string();
  const mode_t was = ::umask(077);
  { auto held = station::ProcessLock::acquire(file, "device X"); }
  ::umask(was);
  struct stat st {};
  ASSERT_EQ(::stat(file.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644U);
}

// Debian's fs.protected_regular = 2 refuses an O_CREAT open of another user's file in a sticky
// world-writable directory, even to root: the service's lock files in /run/lock then blocked
// `sudo station ...` (and the other way round) with "Permission denied".
TEST(ProcessLock, AnotherUsersLockFileInAStickyDirectoryCanBeLocked) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to make a file owned by another user";
  const auto dir = fresh_dir("sticky");
  ASSERT_EQ(::chmod(dir.c_str(), 01777), 0);
  const auto file = (dir / "x.lock").string();
  { auto made = station::ProcessLock::acquire(file, "device X"); }
  ASSERT_EQ(::chown(file.c_str(), 65534, 65534), 0);  // nobody's, 0644
  auto held = station::ProcessLock::acquire(file, "device X");
  EXPECT_EQ(held.path(), file);
}
