// Serve control: validation on the HTTP thread, hand-over to the serve loop under a lock.
#include "station/http/serve_control.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "station/common/input_error.hpp"

namespace station {

namespace {

bool plain_name(const std::string& s) {
  if (s.empty() || s.size() > 64 || s.front() == '.') return false;
  for (const char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'))
      return false;
  return true;
}

}  // namespace

Protocol ServeControl::find_protocol(const std::string& name) const {
  if (!plain_name(name))
    throw InputError(
        fmt::format("protocol '{}': a name of letters, digits, '_', '-', '.' "
                    "(at most 64), not a path",
                    name.substr(0, 80)));
  if (!protocol_dir_.empty()) {
    const auto file = std::filesystem::path(protocol_dir_) / (name + ".toml");
    if (std::filesystem::is_regular_file(file)) return load_protocol(file.string());
  }
  const auto shipped = builtin_protocol_names();
  if (std::find(shipped.begin(), shipped.end(), name) == shipped.end())
    throw InputError(
        fmt::format("protocol '{}': unknown (shipped: {}{})", name, fmt::join(shipped, ", "),
                    protocol_dir_.empty() ? "" : "; or NAME.toml in " + protocol_dir_));
  return load_protocol(name);
}

http::ControlReply ServeControl::start(const std::string& protocol,
                                       const std::string& operator_name,
                                       const std::vector<SlotGyro>& gyros) {
  Protocol p;
  try {
    p = find_protocol(protocol);
    const auto problems = check_gyros_ ? check_gyros_(gyros) : std::vector<std::string>{};
    if (!problems.empty()) throw InputError::lines(problems);
  } catch (const InputError& e) {
    return {400, e.what()};
  }
  std::unique_lock lock(mu_);
  if (busy_ || pending_) return {409, "a run is going on; stop it first"};
  // A full disk is the server's own trouble, not a state of the run resource a client can
  // change: 503 (RFC 9110 15.6.4), as when the run could not be created; a rig's fault is 409.
  if (!fault_.empty() && storage_fault_)
    return {503, fmt::format("the station cannot record a run now: {}", fault_)};
  if (!fault_.empty()) return {409, fmt::format("the rig is not ready: {}", fault_)};
  pending_ = ApiStart{std::move(p), operator_name, gyros};
  const std::uint64_t mine = ++requests_;
  cv_.notify_all();
  // Answer with the run's id once the serve loop created it (it does so before any device I/O),
  // so a client can stop what it started; a slow start still answers 202, without the id.
  cv_.wait_for(lock, std::chrono::seconds(5), [&] { return answered_ >= mine; });
  const std::int64_t id = answered_ >= mine ? started_id_ : 0;
  if (answered_ >= mine && id == 0)
    return {start_status_, fmt::format("the run could not be started: {}", start_error_)};
  return {202, fmt::format("starting protocol '{}'", protocol), id};
}

http::ControlReply ServeControl::stop(std::int64_t run_id, bool abort) {
  if (abort) run_abort_.store(true);
  run_stop_.store(true);
  return {202, fmt::format("run {} ends at the next tick ({})", run_id,
                           abort ? "aborted: no bins, no fit" : "stopped: binned and fitted")};
}

std::optional<ApiStart> ServeControl::next(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, timeout, [this] { return pending_.has_value() || woken_; });
  woken_ = false;
  std::optional<ApiStart> r;
  r.swap(pending_);
  if (r) busy_ = true;
  return r;
}

void ServeControl::set_busy(bool busy) {
  std::lock_guard lock(mu_);
  busy_ = busy;
}

void ServeControl::set_fault(const std::string& fault, bool storage) {
  std::lock_guard lock(mu_);
  fault_ = fault;
  storage_fault_ = storage;
}

void ServeControl::started(std::int64_t run_id) {
  std::lock_guard lock(mu_);
  started_id_ = run_id;
  start_error_.clear();
  answered_ = requests_;
  cv_.notify_all();
}

void ServeControl::start_failed(const std::string& why, int status) {
  std::lock_guard lock(mu_);
  started_id_ = 0;
  start_error_ = why;
  start_status_ = status;
  answered_ = requests_;
  cv_.notify_all();
}

void ServeControl::wake() {
  std::lock_guard lock(mu_);
  woken_ = true;
  cv_.notify_all();
}

}  // namespace station
