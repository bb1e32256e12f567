// Token file: created with O_EXCL and mode 0600, read back and checked.
#include "station/http/token.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstring>

#include "station/common/input_error.hpp"

namespace station::http {

namespace {

std::string random_hex(std::size_t bytes) {
  std::array<unsigned char, 64> buf{};
  std::size_t got = 0;
  while (got < bytes) {
    const ssize_t n = ::getrandom(buf.data() + got, bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw InputError(fmt::format("getrandom: {}", std::strerror(errno)));
    got += static_cast<std::size_t>(n);
  }
  std::string hex;
  for (std::size_t i = 0; i < bytes; ++i) hex += fmt::format("{:02x}", buf[i]);
  return hex;
}

void create_token_file(const std::string& path) {
  // Written under a temporary name and linked into place: a crash never leaves an empty token.
  const std::string tmp = fmt::format("{}.{}.tmp", path, ::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    if (errno == EEXIST) return;  // another start created it meanwhile: read that one
    throw InputError(
        fmt::format("{}: cannot create the API token file: {}", path, std::strerror(errno)));
  }
  const std::string line = random_hex(32) + "\n";
  const bool ok = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  // link() fails with EEXIST when another start made the file meanwhile: that one is read.
  const bool linked = ok && synced && (::link(tmp.c_str(), path.c_str()) == 0 || errno == EEXIST);
  ::unlink(tmp.c_str());
  if (!linked) throw InputError(fmt::format("{}: cannot write the API token file", path));
}

}  // namespace

std::string load_or_create_token(const std::string& path) {
  // Opened without following a symlink and checked on the open descriptor (no stat/open race):
  // a regular file, ours, readable by nobody else, one line of >= 32 token characters.
  // O_NONBLOCK: opening a FIFO (or a device) must not wait for a writer; it is then refused as
  // not a regular file before any read.
  constexpr int kFlags = O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK;
  int fd = ::open(path.c_str(), kFlags);
  if (fd < 0 && errno == ENOENT) {
    create_token_file(path);
    fd = ::open(path.c_str(), kFlags);
  }
  if (fd < 0)
    throw InputError(
        fmt::format("{}: API token file: {}", path,
                    errno == ELOOP ? "a symbolic link (refused)" : std::strerror(errno)));
  struct stat st {};
  std::string text(4096, '\0');
  const bool stated = ::fstat(fd, &st) == 0;
  const ssize_t n = stated && S_ISREG(st.st_mode) ? ::read(fd, text.data(), text.size()) : -1;
  ::close(fd);
  if (!stated || !S_ISREG(st.st_mode))
    throw InputError(fmt::format("{}: API token: not a regular file", path));
  if (st.st_uid != ::geteuid())
    throw InputError(fmt::format("{}: API token file belongs to uid {}, not to this daemon ({})",
                                 path, st.st_uid, ::geteuid()));
  if ((st.st_mode & 077) != 0)
    throw InputError(
        fmt::format("{}: API token file is readable by others (mode {:o}); "
                    "chmod 600 it",
                    path, st.st_mode & 0777));
  if (n < 0) throw InputError(fmt::format("{}: API token file: cannot read", path));
  text.resize(static_cast<std::size_t>(n));
  std::string token = text.substr(0, text.find('\n'));
  while (!token.empty() && (token.back() == '\r' || token.back() == ' ')) token.pop_back();
  const bool plain = std::all_of(token.begin(), token.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.';
  });
  if (token.size() < 32 || !plain)
    throw InputError(
        fmt::format("{}: API token must be one line of >= 32 letters, digits, "
                    "'-', '_' or '.' (delete the file: a new one is made)",
                    path));
  return token;
}

bool bearer_matches(std::string_view header, std::string_view token) {
  constexpr std::string_view kPrefix = "Bearer ";
  if (header.size() != kPrefix.size() + token.size() || !header.starts_with(kPrefix)) return false;
  unsigned char diff = 0;  // constant time in the token's length: no early exit
  for (std::size_t i = 0; i < token.size(); ++i)
    diff |= static_cast<unsigned char>(header[kPrefix.size() + i] ^ token[i]);
  return diff == 0;
}

}  // namespace station::http
