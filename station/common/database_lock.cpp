// One exclusive flock(2) per database file per writing process.
#include "station/common/database_lock.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <utility>

#include "station/common/input_error.hpp"

namespace station {

void (*database_lock_hooks::after_create)(const std::string& path) = nullptr;

using Key = std::pair<unsigned long long, unsigned long long>;  // (st_dev, st_ino)

struct HeldDatabase {
  int fd = -1;
  Key key;
  bool created = false;  ///< this hold made the (empty) file: remove it if still empty
  std::string path;
  ~HeldDatabase();
};

namespace {

// Every hold of this process, by file. The mutex is held across a whole acquisition and across a
// release: no descriptor of a file is opened or closed by another thread while a hold on it is
// being decided.
std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::map<Key, std::weak_ptr<HeldDatabase>>& registry() {
  static std::map<Key, std::weak_ptr<HeldDatabase>> r;
  return r;
}

int open_database_file(const std::string& path, bool create, bool& created) {
  created = false;
  for (int attempt = 0; attempt < 3; ++attempt) {
    int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0 && (errno == EACCES || errno == EROFS))
      fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);  // flock works on a read-only descriptor
    if (fd >= 0 || errno != ENOENT || !create) return fd;
    fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd >= 0) {
      created = true;
      if (database_lock_hooks::after_create) database_lock_hooks::after_create(path);
      return fd;
    }
    if (errno != EEXIST) return fd;  // another process created it just now: open that one
  }
  return -1;
}

Key key_of(int fd, const std::string& path) {
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw InputError(fmt::format("{}: not a regular file; a database is one", path));
  }
  return {static_cast<unsigned long long>(st.st_dev), static_cast<unsigned long long>(st.st_ino)};
}

std::string holders_text(const std::vector<FlockHolder>& holders) {
  std::string out;
  for (const auto& h : holders) {
    out += (out.empty() ? "" : ", ") + describe_process(h.pid);
  }
  return out.empty() ? "another station process" : out;
}

// Takes LOCK_EX on `fd` at once; throws naming the holder.
void lock_exclusive(int fd, const std::string& path, Key key) {
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return;
  const int err = errno;
  if (err != EWOULDBLOCK)
    throw InputError(fmt::format("{}: cannot lock the database: {}", path, std::strerror(err)));
  throw InputError(fmt::format(
      "{}: database is in use by {}; nothing was touched (one writer at a time: a daemon holds "
      "it for its whole life, a writing command while it runs)",
      path, holders_text(flock_holders(key.first, key.second))));
}

}  // namespace

HeldDatabase::~HeldDatabase() {
  const std::lock_guard<std::mutex> guard(registry_mutex());
  const auto it = registry().find(key);
  if (it != registry().end() && it->second.expired()) registry().erase(it);
  // A database file this hold made and nothing wrote (a run refused before its first write)
  // leaves no empty file behind; only while the name still points at the same empty inode.
  struct stat mine {
  }, named{};
  if (created && ::fstat(fd, &mine) == 0 && mine.st_size == 0 &&
      ::stat(path.c_str(), &named) == 0 && named.st_ino == mine.st_ino &&
      named.st_dev == mine.st_dev) {
    (void)::unlink(path.c_str());
  }
  ::close(fd);  // the last descriptor of the hold: releases the flock
}

namespace {

// The hold this process already has on the file at `path`, found by stat(2): no descriptor of the
// file is opened (closing one would drop the POSIX locks of this process's connections on it).
std::shared_ptr<HeldDatabase> hold_of(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return nullptr;
  const auto it = registry().find(
      {static_cast<unsigned long long>(st.st_dev), static_cast<unsigned long long>(st.st_ino)});
  return it == registry().end() ? nullptr : it->second.lock();
}

std::shared_ptr<HeldDatabase> new_hold(int fd, Key key, bool created, const std::string& path) {
  auto held = std::make_shared<HeldDatabase>();
  held->fd = fd;
  held->key = key;
  held->created = created;
  held->path = path;
  registry()[key] = held;
  return held;
}

}  // namespace

namespace {

// Descriptors of files this process could not lock, one per file (inode), reused by every later
// attempt on it: a refusal opens no new descriptor and closes none. Closing one is not safe: the
// lock is a flock(2), held by its open file description and untouched by closing another, but
// SQLite's locks are POSIX fcntl(2) locks, which closing *any* descriptor of the file drops for
// the whole process (fcntl(2), "Advisory record locking"), and this process may be reading the
// file through SQLite.
std::map<Key, int>& refused_descriptors() {
  static std::map<Key, int> r;
  return r;
}

// A descriptor of `path`: the one kept from an earlier refusal on the same file, else a new one.
int descriptor_of(const std::string& path, bool create, bool& created) {
  created = false;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    const auto it = refused_descriptors().find(
        {static_cast<unsigned long long>(st.st_dev), static_cast<unsigned long long>(st.st_ino)});
    if (it != refused_descriptors().end()) return it->second;
  }
  return open_database_file(path, create, created);
}

// True when `path` still names the file `key` (it was not removed nor replaced while locking).
bool still_named(const std::string& path, Key key) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && Key{static_cast<unsigned long long>(st.st_dev),
                                               static_cast<unsigned long long>(st.st_ino)} == key;
}

}  // namespace

DatabaseHold DatabaseHold::writer(const std::string& path, bool create) {
  const std::lock_guard<std::mutex> guard(registry_mutex());
  for (int attempt = 0;; ++attempt) {
    if (auto held = hold_of(path)) return DatabaseHold(held);
    bool created = false;
    const int fd = descriptor_of(path, create, created);
    if (fd < 0) {
      throw InputError(fmt::format("{}: cannot open the database: {}", path, std::strerror(errno)));
    }
    const Key key = key_of(fd, path);
    refused_descriptors().erase(key);
    try {
      lock_exclusive(fd, path, key);
    } catch (...) {
      // Never unlinked, even when this attempt created it: whoever holds the lock now owns the
      // file and may be writing it.
      refused_descriptors()[key] = fd;
      throw;
    }
    // A holder that removed the (empty) file as it ended, or a rename over it, leaves this lock
    // on a file no longer at `path`: released, and the name opened again.
    if (still_named(path, key)) return DatabaseHold(new_hold(fd, key, created, path));
    ::flock(fd, LOCK_UN);
    refused_descriptors()[key] = fd;
    if (attempt == 3)
      throw InputError(fmt::format("{}: the file was replaced while it was locked; retry", path));
  }
}

bool DatabaseHold::held_here(const std::string& path) {
  const std::lock_guard<std::mutex> guard(registry_mutex());
  return hold_of(path) != nullptr;
}

std::vector<FlockHolder> flock_holders(unsigned long long dev, unsigned long long ino) {
  // proc(5), /proc/locks: "1: FLOCK  ADVISORY  WRITE 4242 fd:01:1234567 0 EOF"; a waiter's line
  // has "->" after the number. The device is MAJOR:MINOR in hex, the inode in decimal.
  const std::string want = fmt::format("{:02x}:{:02x}:{}", major(static_cast<dev_t>(dev)),
                                       minor(static_cast<dev_t>(dev)), ino);
  std::ifstream locks("/proc/locks");
  std::vector<FlockHolder> out;
  std::string line;
  while (std::getline(locks, line)) {
    std::istringstream in(line);
    std::string number, type, advisory, mode, pid, where;
    in >> number >> type;
    if (type != "FLOCK") continue;  // a waiter ("->") or a POSIX lock (SQLite's own)
    in >> advisory >> mode >> pid >> where;
    if (where == want) out.push_back({pid, mode == "WRITE"});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const FlockHolder& a, const FlockHolder& b) { return a.write && !b.write; });
  return out;
}

std::string describe_process(const std::string& pid) {
  std::ifstream in("/proc/" + pid + "/cmdline", std::ios::binary);
  std::vector<std::string> argv;
  for (std::string arg; std::getline(in, arg, '\0');) argv.push_back(arg);
  if (argv.empty()) return fmt::format("pid {}", pid);
  const std::string program = argv[0].substr(argv[0].find_last_of('/') + 1);
  if (program == "station" && argv.size() > 1)
    return fmt::format("station {} (pid {})", InputError::one_line(argv[1]), pid);
  return fmt::format("{} (pid {})", InputError::one_line(program), pid);
}

std::string name_opened_by(const std::string& pid, unsigned long long dev, unsigned long long ino) {
  const std::string dir = "/proc/" + pid + "/fd";
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) return {};
  std::string found;
  while (const dirent* e = ::readdir(d)) {
    const std::string fd_path = dir + "/" + e->d_name;
    struct stat st {};
    if (e->d_name[0] == '.' || ::stat(fd_path.c_str(), &st) != 0) continue;
    if (static_cast<unsigned long long>(st.st_dev) != dev ||
        static_cast<unsigned long long>(st.st_ino) != ino)
      continue;
    char target[4096] = {};
    const ssize_t n = ::readlink(fd_path.c_str(), target, sizeof target - 1);
    if (n > 0) found.assign(target, static_cast<std::size_t>(n));
    break;
  }
  ::closedir(d);
  return found;
}

}  // namespace station
