// Token file: created with O_EXCL and mode 0600, read back and checked.
#include "station/http/token.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>

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
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    if (errno == EEXIST) return;  // another start created it meanwhile: read that one
    throw InputError(
        fmt::format("{}: cannot create the API token file: {}", path, std::strerror(errno)));
  }
  const std::string line = random_hex(32) + "\n";
  const bool ok = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (!ok || !synced) {
    ::unlink(path.c_str());
    throw InputError(fmt::format("{}: cannot write the API token file", path));
  }
}

}  // namespace

std::string load_or_create_token(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno != ENOENT)
      throw InputError(fmt::format("{}: API token file: {}", path, std::strerror(errno)));
    create_token_file(path);
    if (::stat(path.c_str(), &st) != 0)
      throw InputError(fmt::format("{}: API token file: {}", path, std::strerror(errno)));
  }
  if (!S_ISREG(st.st_mode)) throw InputError(fmt::format("{}: API token: not a file", path));
  if ((st.st_mode & 077) != 0)
    throw InputError(
        fmt::format("{}: API token file is readable by others (mode {:o}); "
                    "chmod 600 it",
                    path, st.st_mode & 0777));
  std::ifstream in(path);
  std::string token;
  std::getline(in, token);
  while (!token.empty() && (token.back() == '\r' || token.back() == ' ')) token.pop_back();
  if (token.size() < 16)
    throw InputError(fmt::format("{}: API token must be one line of >= 16 characters", path));
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
