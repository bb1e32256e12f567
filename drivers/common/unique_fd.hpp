// Move-only owner of a POSIX file descriptor: closes it exactly once.
#pragma once

#include <unistd.h>

#include <utility>

namespace station::drivers {

/// RAII holder of one file descriptor (-1 = none). Move-only.
class UniqueFd {
 public:
  UniqueFd() = default;
  /// Takes ownership of fd.
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() { reset(); }
  UniqueFd(UniqueFd&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
  UniqueFd& operator=(UniqueFd&& o) noexcept {
    if (this != &o) reset(std::exchange(o.fd_, -1));
    return *this;
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;

  /// The descriptor, still owned.
  int get() const { return fd_; }
  /// Whether a descriptor is held.
  bool valid() const { return fd_ >= 0; }
  /// Gives up ownership and returns the descriptor.
  int release() { return std::exchange(fd_, -1); }
  /// Closes the held descriptor (if any) and takes fd.
  void reset(int fd = -1) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = fd;
  }

 private:
  int fd_ = -1;
};

}  // namespace station::drivers
