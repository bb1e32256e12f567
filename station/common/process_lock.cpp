// flock(2)-based single-instance locks for databases and devices.
#include "station/common/process_lock.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "station/common/input_error.hpp"

namespace station {
namespace {

std::string read_holder(int fd) {
  char buf[32] = {};
  const ssize_t n = pread(fd, buf, sizeof buf - 1, 0);
  std::string pid = n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return pid.empty() ? "unknown" : pid;
}

// The lock file, shared by every user that runs a station process (the service's user, an
// operator, root). flock(2) works on any open descriptor, so an existing file is opened without
// O_CREAT (read-write to leave the PID note, else read-only): in a world-writable sticky
// directory such as /run/lock, fs.protected_regular=2 (Debian's default) refuses an O_CREAT open
// of another user's file even to root. A new file is made readable by all (0644 whatever the
// umask), so the next user can open it.
int open_lock_file(const std::string& path) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    int fd = ::open(path.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0 && errno == EACCES) fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd >= 0 || errno != ENOENT) return fd;
    fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0) {
      (void)::fchmod(fd, 0644);
      return fd;
    }
    if (errno != EEXIST) return fd;  // another process created it just now: open that one
  }
  return -1;
}

}  // namespace

ProcessLock ProcessLock::acquire(const std::string& lock_path, const std::string& what) {
  const int fd = open_lock_file(lock_path);
  if (fd < 0) {
    throw InputError(fmt::format("{}: cannot open the lock file for {}: {}", lock_path, what,
                                 std::strerror(errno)));
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    const std::string holder = read_holder(fd);
    ::close(fd);
    if (err == EWOULDBLOCK) {
      throw LockHeld(fmt::format("{}: {} is in use by another station process (pid {})", lock_path,
                                 what, holder),
                     holder);
    }
    throw InputError(fmt::format("{}: cannot lock {}: {}", lock_path, what, std::strerror(err)));
  }
  const std::string pid = fmt::format("{}\n", ::getpid());
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) < 0) {
    // The lock itself is held; only the PID note failed. Say so in the next refusal.
  }
  return ProcessLock(fd, lock_path);
}

ProcessLock ProcessLock::acquire_database(const std::string& db_path) {
  ProcessLock lock(-1, db_path);
  lock.database_ = DatabaseHold::writer(db_path, true);
  return lock;
}

ProcessLock::ProcessLock(ProcessLock&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      path_(std::move(other.path_)),
      database_(std::exchange(other.database_, std::nullopt)) {}

ProcessLock& ProcessLock::operator=(ProcessLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    database_ = std::exchange(other.database_, std::nullopt);
  }
  return *this;
}

ProcessLock::~ProcessLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the last fd releases the flock
}

std::string device_lock_path(const std::string& endpoint) {
  std::string dir = "/run/lock";
  if (::access(dir.c_str(), W_OK) != 0) {
    const char* tmp = std::getenv("TMPDIR");
    dir = tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
  }
  std::string name;
  for (const char c : endpoint) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '-';
    name += keep ? c : '_';
  }
  return fmt::format("{}/gyro-station.{}.lock", dir, name);
}

}  // namespace station
