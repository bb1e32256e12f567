// Who may write a station database file, decided on the file itself (its device and inode: a hard
// link, a symlink, `./` or `..` is the same lock): a writer holds an exclusive flock(2) — a daemon
// for its whole life, a writing command (fit, release, verify, sync) while it runs. Readers take
// no lock (SQLite's WAL lets them read beside a writer); they look at who holds it.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace station {

struct HeldDatabase;

/// This process's flock on one database file: one per file (inode) for the whole process, shared
/// by every writing connection the process opens on it and released when the last one ends. Closing
/// any descriptor of a file drops all of the process's POSIX locks on it, SQLite's included
/// (fcntl(2), "Advisory record locking"), so the lock's descriptor is closed only when no
/// connection remains.
class DatabaseHold {
 public:
  /// Exclusive, without waiting: refuses (InputError "PATH: database is in use by station run
  /// (pid N); nothing was touched ...") when another process holds it. `create`: a missing file
  /// is created empty (0644), and removed again when the hold ends if nothing was written to it;
  /// never when the lock is refused, even on a file this call created (another process locked it
  /// first and owns it now). A refusal keeps one descriptor per file, reused by every later
  /// attempt on that file (closing it would drop SQLite's POSIX locks of this process on it).
  /// The lock taken, `path` must still name the locked file, or it is released and taken again.
  static DatabaseHold writer(const std::string& path, bool create);
  /// True when this process holds the file at `path` (it writes it). Opens no descriptor.
  static bool held_here(const std::string& path);

 private:
  explicit DatabaseHold(std::shared_ptr<HeldDatabase> held) : held_(std::move(held)) {}
  std::shared_ptr<HeldDatabase> held_;
};

/// For tests only: called by DatabaseHold::writer between creating a missing file and locking it
/// (the instant another process may open and lock the new file first).
struct database_lock_hooks {
  static void (*after_create)(const std::string& path);
};

/// A process holding a flock(2) on a file, from /proc/locks.
struct FlockHolder {
  std::string pid;
  bool write = false;  ///< exclusive (LOCK_EX); false: shared
};

/// Every flock(2) on the file (dev, ino), writers first.
std::vector<FlockHolder> flock_holders(unsigned long long dev, unsigned long long ino);

/// "station run (pid 4242)": the command of process `pid` (`station` and its subcommand, else
/// the program's name) from /proc/PID/cmdline, with the PID.
std::string describe_process(const std::string& pid);

/// The name process `pid` opened the file (dev, ino) by (/proc/PID/fd), empty when not readable.
std::string name_opened_by(const std::string& pid, unsigned long long dev, unsigned long long ino);

}  // namespace station
