// What the API can ask of the daemon that serves it: start a run, end the running one. `serve`
// implements both; `run` (one run per process) refuses to start another.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "station/daemon/run_gyros.hpp"

namespace station::http {

/// The answer to a control request: an HTTP status and a one-line message.
struct ControlReply {
  int status = 202;
  std::string message;
  std::int64_t run_id = 0;  ///< a started run's id (0: not known)
};

/// Control of the daemon's runs. Called on HTTP threads: implementations are thread-safe.
class RunControl {
 public:
  virtual ~RunControl() = default;
  /// Starts `protocol` with the gyros given (slots not given: the configuration's defaults).
  virtual ControlReply start(const std::string& protocol, const std::string& operator_name,
                             const std::vector<SlotGyro>& gyros) = 0;
  /// Ends the running run `run_id` (the caller checked it is the running one).
  virtual ControlReply stop(std::int64_t run_id, bool abort) = 0;
};

}  // namespace station::http
