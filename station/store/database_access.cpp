// The lock and the way of reading a station database file, decided before SQLite opens it.
#include "station/store/database_access.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "station/common/database_names.hpp"
#include "station/common/input_error.hpp"
#include "station/store/sqlite.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;

bool beside(const std::string& name, const char* suffix) {
  std::error_code ec;
  return fs::exists(name + suffix, ec);
}

// A reader that found another process writing the file: its WAL must sit beside this name.
void refuse_other_writers_name(const std::string& path, const std::string& own) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  const auto dev = static_cast<unsigned long long>(st.st_dev);
  const auto ino = static_cast<unsigned long long>(st.st_ino);
  const auto holders = flock_holders(dev, ino);
  if (holders.empty()) return;  // not a writer: the file could not be opened; SQLite says why
  const std::string pid = holders.front().pid;
  const std::string theirs = pid.empty() ? "" : name_opened_by(pid, dev, ino);
  if (!theirs.empty() && theirs == own) return;  // its WAL is not there yet: it is opening
  throw InputError(fmt::format(
      "{}: {} writes this file as {}: its write-ahead log is beside that name, not this one "
      "(SQLite finds the log by the name it opens: sqlite.org/howtocorrupt.html §2.5); nothing "
      "was touched: read it as {}",
      path, describe_process(pid), theirs.empty() ? "another name" : theirs,
      theirs.empty() ? "the writer's name" : theirs));
}

// A writer on a file or directory it cannot write (a read-only mount) says so, instead of SQLite's
// "unable to open database file" once its -shm cannot be made.
void refuse_unwritable(const std::string& path) {
  const std::string own = sqlite_name(path);
  const std::string dir = fs::path(own).parent_path().string();
  for (const std::string& where : {own, dir}) {
    if (::access(where.c_str(), W_OK) == 0) continue;
    throw InputError(fmt::format(
        "{}: a writing command cannot write {} ({}); nothing was touched (read commands work "
        "there)",
        path, where, std::strerror(errno)));
  }
}

}  // namespace

DatabaseAccess claim_database_file(const std::string& path, OpenMode mode) {
  if (path.empty() || path == ":memory:" || path.starts_with("file:")) return {};
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (mode != OpenMode::read_only) {
    if (!exists && mode != OpenMode::create) return {};  // SQLite says it must exist
    // The lock first: a refusal because another process writes it names that process.
    DatabaseAccess access{DatabaseHold::writer(path, mode == OpenMode::create),
                          ReadWay::beside_writer, std::nullopt};
    refuse_log_of_another_name(path);
    refuse_names_not_found(path);
    refuse_unwritable(path);
    return access;
  }
  if (!exists || DatabaseHold::held_here(path)) return {};  // missing, or this process writes it
  const std::string own = sqlite_name(path);
  const bool logs = beside(own, "-wal") || beside(own, "-shm");
  const bool writer = !flock_holders(static_cast<unsigned long long>(st.st_dev),
                                     static_cast<unsigned long long>(st.st_ino))
                           .empty();
  if (writer && !logs) refuse_other_writers_name(path, own);
  refuse_log_of_another_name(path);
  if (writer || logs) return {};
  // Only a connection that can write the file and its directory removes the -wal and -shm.
  const std::string dir = fs::path(own).parent_path().string();
  const bool writable = ::access(own.c_str(), W_OK) == 0 && ::access(dir.c_str(), W_OK) == 0;
  if (writable) return {std::nullopt, ReadWay::leave_nothing, std::nullopt};
  return {std::nullopt, ReadWay::immutable, stamp_of(path)};
}

FileStamp stamp_of(const std::string& path) {
  FileStamp s;
  const std::string own = sqlite_name(path);
  s.logs = beside(own, "-wal") || beside(own, "-shm");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return s;
  // This process has no SQLite connection on the file (an immutable read is chosen only then),
  // so closing this descriptor drops no lock of its.
  struct stat st {};
  char header[8] = {};
  if (::fstat(fd, &st) == 0 && ::pread(fd, header, sizeof header, 24) == sizeof header) {
    s.ino = static_cast<unsigned long long>(st.st_ino);
    s.size_bytes = static_cast<long long>(st.st_size);
    s.mtime_ns = st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec;
    s.ctime_ns = st.st_ctim.tv_sec * 1000000000LL + st.st_ctim.tv_nsec;
    s.header.assign(header, sizeof header);
  }
  ::close(fd);
  return s;
}

std::string immutable_uri(const std::string& path) {
  std::string uri = "file:";
  for (const char c : sqlite_name(path)) {
    if (c == '%' || c == '?' || c == '#')
      uri += fmt::format("%{:02X}", static_cast<unsigned char>(c));
    else
      uri += c;
  }
  return uri + "?immutable=1";
}

}  // namespace station
