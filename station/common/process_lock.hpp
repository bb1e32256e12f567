// One daemon per database and per rig: an exclusive flock(2) on a lock file, held for the life of
// the process (the kernel drops it when the process dies, even by SIGKILL, so a stale file never
// blocks a restart). The holder's PID is written into the file so a refusal can name it.
#pragma once

#include <optional>
#include <string>

#include "station/common/database_lock.hpp"
#include "station/common/input_error.hpp"

namespace station {

/// The refusal of ProcessLock::acquire when another process holds the lock (its PID named).
class LockHeld : public InputError {
 public:
  LockHeld(const std::string& what, std::string holder_pid)
      : InputError(what), holder_pid_(std::move(holder_pid)) {}
  /// The holder's pid as its lock file says it ("" when unreadable).
  const std::string& holder_pid() const { return holder_pid_; }

 private:
  std::string holder_pid_;
};

/// A held exclusive lock on a file. Move-only; released (not deleted) in the destructor.
class ProcessLock {
 public:
  /// Takes the lock on `lock_path` (created 0644 when missing) without waiting; throws LockHeld
  /// "PATH: WHAT is in use by another station process (pid N)" when another process holds it,
  /// InputError naming the OS error otherwise.
  static ProcessLock acquire(const std::string& lock_path, const std::string& what);
  /// Takes the writer's lock on the database file itself (DatabaseHold::writer: its inode, so
  /// every name of it — a hard link, a symlink, `./`, `..` — is the same lock), before anything
  /// reads or writes it. A missing file is created empty (0644), and removed again on release if
  /// nothing was ever written to it. The refusal names the holder's command and PID (from
  /// /proc/locks). SQLite's own locks are POSIX record locks, independent of flock(2) on Linux,
  /// so this lock does not disturb them; every connection of this process on the file shares it.
  static ProcessLock acquire_database(const std::string& db_path);
  ProcessLock(ProcessLock&& other) noexcept;
  ProcessLock& operator=(ProcessLock&& other) noexcept;
  ProcessLock(const ProcessLock&) = delete;
  ProcessLock& operator=(const ProcessLock&) = delete;
  ~ProcessLock();
  const std::string& path() const { return path_; }

 private:
  ProcessLock(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_ = -1;
  std::string path_;
  std::optional<DatabaseHold> database_;  ///< a database file's lock (fd_ unused)
};

/// The lock file of a device endpoint ("tcp://127.0.0.1:5020", "rtu:/dev/ttyUSB0?baud=9600",
/// "unix:/run/x.sock"): one per device, in /run/lock (or $TMPDIR, /tmp when that is not
/// writable), so two configurations naming the same device cannot drive it at once.
std::string device_lock_path(const std::string& endpoint);

}  // namespace station
