// The names a database file is reached by, and the logs beside them.
#include "station/common/database_names.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <filesystem>
#include <set>

#include "station/common/input_error.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;

/// 32 bytes: a WAL file's header; frames follow it (sqlite.org/fileformat2.html, "WAL File
/// Format"). A -wal of only a header (or empty) holds nothing a reader could miss.
constexpr std::uintmax_t kWalHeaderBytes = 32;

bool holds_something(const fs::path& log, const std::string& suffix) {
  std::error_code ec;
  const auto size = fs::file_size(log, ec);
  if (ec) return false;
  return suffix == "-wal" ? size > kWalHeaderBytes : size > 0;
}

bool same_file(const struct stat& a, const fs::path& b) {
  struct stat st {};
  return ::stat(b.c_str(), &st) == 0 && S_ISREG(st.st_mode) && st.st_dev == a.st_dev &&
         st.st_ino == a.st_ino;
}

/// The directories searched for other names of `path`: its own and its symlink's target's.
std::set<fs::path> searched_dirs(const std::string& path) {
  std::set<fs::path> dirs;
  std::error_code ec;
  dirs.insert(fs::canonical(path, ec).parent_path());
  const fs::path given_dir = fs::absolute(path, ec).parent_path();
  if (!ec) dirs.insert(fs::canonical(given_dir, ec));
  dirs.erase(fs::path());
  return dirs;
}

}  // namespace

std::string sqlite_name(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::canonical(path, ec);
  return ec ? fs::absolute(path, ec).lexically_normal().string() : p.string();
}

std::optional<std::string> log_of_another_name(const std::string& path) {
  struct stat me {};
  if (::stat(path.c_str(), &me) != 0) return std::nullopt;
  const fs::path own = sqlite_name(path);
  std::error_code ec;
  for (const auto& dir : searched_dirs(path)) {
    for (fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
         !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      for (const std::string suffix : {"-wal", "-journal"}) {
        if (name.size() <= suffix.size() || !name.ends_with(suffix)) continue;
        const fs::path base = dir / name.substr(0, name.size() - suffix.size());
        if (base != own && same_file(me, base) && holds_something(it->path(), suffix))
          return it->path().string();
      }
    }
  }
  return std::nullopt;
}

void refuse_log_of_another_name(const std::string& path) {
  const auto log = log_of_another_name(path);
  if (!log) return;
  const std::string other = log->substr(0, log->rfind('-'));
  throw InputError(fmt::format(
      "{}: this file is also named {}, and {} beside that name holds writes this name would not "
      "see (SQLite finds the log by the name it opens; a checkpoint through one name overwrites "
      "what the other's log holds: sqlite.org/howtocorrupt.html §2.5); nothing was touched: open "
      "it as {}",
      path, other, *log, other));
}

void refuse_names_not_found(const std::string& path) {
  struct stat me {};
  if (::stat(path.c_str(), &me) != 0 || me.st_nlink <= 1) return;
  std::set<std::string> found;
  std::error_code ec;
  for (const auto& dir : searched_dirs(path))
    for (fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
         !ec && it != end; it.increment(ec))
      if (struct stat st{}; ::lstat(it->path().c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
                            st.st_dev == me.st_dev && st.st_ino == me.st_ino)
        found.insert(it->path().string());  // a hard link, not a symlink to it
  if (found.size() >= me.st_nlink) return;
  std::string names;
  for (const auto& n : found) names += (names.empty() ? "" : ", ") + n;
  throw InputError(fmt::format(
      "{}: this file has {} names (hard links) and only {} are here ({}); a write-ahead log beside "
      "a name elsewhere could not be seen (SQLite finds it by the name it opens: "
      "sqlite.org/howtocorrupt.html §2.5); nothing was touched: remove the other links, or "
      "write it as a name whose directory holds them all",
      path, me.st_nlink, found.size(), names));
}

}  // namespace station
