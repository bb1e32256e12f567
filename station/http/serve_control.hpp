// `station serve`'s run control: the API's start/stop requests handed to the serve loop. A run
// is started by protocol name only (a shipped one, or NAME.toml in [http] protocol_dir): a
// request never names a path. Its gyros (the body's "slots") are checked here, before the
// request reaches the loop: each problem is a line of the 400's error.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "station/config/protocol.hpp"
#include "station/http/run_control.hpp"

namespace station {

/// A run the API asked for (the serve loop makes it a StartRequest, run_start.hpp).
struct ApiStart {
  Protocol protocol;
  std::string operator_name;
  std::vector<SlotGyro> gyros;  ///< the body's slots (none: the configuration's defaults)
};

/// What is wrong with a start's gyros, one line each (run_gyros.hpp gyro_problems).
using GyroCheck = std::function<std::vector<std::string>(const std::vector<SlotGyro>&)>;

class ServeControl final : public http::RunControl {
 public:
  ServeControl(std::string protocol_dir, std::atomic<bool>& run_stop, std::atomic<bool>& run_abort,
               GyroCheck check_gyros = {})
      : protocol_dir_(std::move(protocol_dir)),
        run_stop_(run_stop),
        run_abort_(run_abort),
        check_gyros_(std::move(check_gyros)) {}
  http::ControlReply start(const std::string& protocol, const std::string& operator_name,
                           const std::vector<SlotGyro>& gyros) override;
  http::ControlReply stop(std::int64_t run_id, bool abort) override;

  /// The serve loop: the next start request, waiting up to `timeout` (or until woken).
  std::optional<ApiStart> next(std::chrono::milliseconds timeout);
  /// The serve loop: a run is going on (start requests are refused meanwhile).
  void set_busy(bool busy);
  /// The serve loop: why the idle rig cannot start a run (empty: it can); `storage`: the fault
  /// is the store's (a start is then 503, the station cannot record; a rig's fault is 409).
  void set_fault(const std::string& fault, bool storage = false);
  /// The serve loop: the run of the last request was created with this id (start() answers it).
  void started(std::int64_t run_id);
  /// The serve loop: the run of the last request could not be created; start() answers
  /// `status`: 503 when the station could not record it, 400 when the request itself was
  /// refused (a protocol the rig cannot run: beyond the table's limits, no relay).
  void start_failed(const std::string& why, int status = 503);
  /// Wakes next() (shutdown).
  void wake();

 private:
  /// The protocol called `name`; throws InputError for a bad or unknown name.
  Protocol find_protocol(const std::string& name) const;

  const std::string protocol_dir_;
  std::atomic<bool>& run_stop_;
  std::atomic<bool>& run_abort_;
  const GyroCheck check_gyros_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::optional<ApiStart> pending_;
  bool busy_ = false, woken_ = false;
  std::uint64_t requests_ = 0, answered_ = 0;  ///< start requests taken / whose run exists
  std::int64_t started_id_ = 0;
  std::string start_error_;  ///< why the last request's run was not created
  int start_status_ = 503;   ///< and the answer it gets
  std::string fault_;
  bool storage_fault_ = false;
};

}  // namespace station
