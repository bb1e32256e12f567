// One daemon per database and per rig: an exclusive flock(2) on a lock file, held for the life of
// the process (the kernel drops it when the process dies, even by SIGKILL, so a stale file never
// blocks a restart). The holder's PID is written into the file so a refusal can name it.
#pragma once

#include <string>

namespace station {

/// A held exclusive lock on a file. Move-only; released (not deleted) in the destructor.
class ProcessLock {
 public:
  /// Takes the lock on `lock_path` (created 0644 when missing) without waiting; throws InputError
  /// "PATH: held by pid N (WHAT)" when another process holds it, or naming the OS error.
  static ProcessLock acquire(const std::string& lock_path, const std::string& what);
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
};

/// The lock file of a device endpoint ("tcp://127.0.0.1:5020", "rtu:/dev/ttyUSB0?baud=9600",
/// "unix:/run/x.sock"): one per device, in /run/lock (or $TMPDIR, /tmp when that is not
/// writable), so two configurations naming the same device cannot drive it at once.
std::string device_lock_path(const std::string& endpoint);

}  // namespace station
