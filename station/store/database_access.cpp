// The lock and the way of reading a station database file, decided before SQLite opens it.
#include "station/store/database_access.hpp"

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
    DatabaseAccess access{DatabaseHold::writer(path, mode == OpenMode::create)};
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
  return {std::nullopt, writable ? ReadWay::leave_nothing : ReadWay::immutable};
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
