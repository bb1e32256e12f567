// Outage bookkeeping per device and record-window loss per slot.
#include "station/daemon/outages.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace station {

std::optional<OutageNews> OutageTracker::observe(const std::string& device, double t_s,
                                                 std::optional<bool> answered,
                                                 std::string_view error) {
  auto it = open_.find(device);
  if (it != open_.end()) {
    if (answered.value_or(false) == false) {  // still down, or covered by another outage
      ++it->second.ticks_lost;
      return std::nullopt;
    }
    Outage o = std::move(it->second);
    open_.erase(it);
    o.end_s = t_s;
    o.recovered = true;
    return OutageNews{OutageChange::ended, std::move(o)};
  }
  if (!answered || *answered) return std::nullopt;
  Outage o{device, t_s, t_s, 1, false, std::string(error)};
  open_.emplace(device, o);
  return OutageNews{OutageChange::started, std::move(o)};
}

std::vector<Outage> OutageTracker::close_all(double t_s) {
  std::vector<Outage> out;
  for (auto& [device, o] : open_) {
    o.end_s = t_s;
    out.push_back(std::move(o));
  }
  open_.clear();
  return out;
}

nlohmann::json outage_json(const Outage& o, OutageEnd ended) {
  const char* const how = ended == OutageEnd::answered  ? "answered"
                          : ended == OutageEnd::run_end ? "run_end"
                                                        : "abort";
  return {{"device", o.device},
          {"start_s", o.start_s},
          {"end_s", o.end_s},
          {"ticks_lost", o.ticks_lost},
          {"ended", how}};
}

WindowLoss record_window_loss(const std::vector<SampleRow>& recorded, double period_s) {
  WindowLoss w;
  if (recorded.empty() || !(period_s > 0)) return w;
  const double span_s = recorded.back().t_s - recorded.front().t_s;
  w.ticks = static_cast<std::int64_t>(std::llround(span_s / period_s)) + 1;
  std::int64_t with_rate = 0;
  for (const auto& r : recorded) with_rate += r.rate_dph ? 1 : 0;
  w.lost = w.ticks - with_rate;
  return w;
}

}  // namespace station
