// Link outages, decided from what answered each tick (no I/O): one start and one end per outage
// of a device, with the ticks it cost; and how much of a slot's record window has no rate.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "station/store/store.hpp"

namespace station {

/// One outage of one device.
struct Outage {
  std::string device;           ///< "chamber", "turntable", "can", "can node 3", ...
  double start_s = 0;           ///< first tick the device did not answer, run seconds
  double end_s = 0;             ///< first tick it answered again (or the run's last tick)
  std::int64_t ticks_lost = 0;  ///< ticks observed without an answer
  bool recovered = false;       ///< false: still down when the run ended
  std::string error;            ///< why the first lost tick failed
};

/// Whether an observation started or ended an outage.
enum class OutageChange : std::uint8_t { started, ended };

/// What an observation changed.
struct OutageNews {
  OutageChange change;
  Outage outage;  ///< the outage as it stands (ended: complete)
};

/// Outages per device, fed once per tick per device. Not thread-safe.
class OutageTracker {
 public:
  /// One tick's news about `device` at `t_s`: it answered (true), did not (false; `error` says
  /// why), or there is no news (std::nullopt: another outage covers it, e.g. a board behind a
  /// lost bus; an open outage counts the tick, none starts or ends). Returns a start or an end.
  std::optional<OutageNews> observe(const std::string& device, double t_s,
                                    std::optional<bool> answered, std::string_view error = {});
  /// Ends every open outage at the run's last tick `t_s` (recovered = false), in device order.
  std::vector<Outage> close_all(double t_s);
  /// Carries on an outage a killed daemon left open (resume): the next observation of its device
  /// counts a lost tick or ends it, as if the process had never stopped.
  void restore(Outage o) { open_[o.device] = std::move(o); }
  /// Whether `device` is in an outage now.
  bool down(const std::string& device) const { return open_.count(device) != 0; }

 private:
  std::map<std::string, Outage> open_;
};

/// How an outage ended: the device answered again, or the run ended (or was aborted) first.
enum class OutageEnd { answered, run_end, abort };

/// An 'outage' event's data (schemas/events.md): {"device","start_s","end_s","ticks_lost",
/// "ended"} with `ended` "answered", "run_end" or "abort".
nlohmann::json outage_json(const Outage& o, OutageEnd ended);

/// Ticks of a record window and how many of them have no rate.
struct WindowLoss {
  std::int64_t ticks = 0;  ///< ticks from the first to the last recorded sample, both included
  std::int64_t lost = 0;   ///< of them: no sample, or a sample without a rate
  /// lost / ticks (0 for an empty window).
  double share() const { return ticks > 0 ? static_cast<double>(lost) / ticks : 0.0; }
};

/// The loss of one slot's record window from its recorded samples (recording = true, by time)
/// at a tick period of `period_s`: ticks the daemon never stored (down, skipped) count as lost.
WindowLoss record_window_loss(const std::vector<SampleRow>& recorded, double period_s);

}  // namespace station
