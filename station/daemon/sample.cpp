// Counter reading -> sample (see sample.hpp).
#include "station/daemon/sample.hpp"

#include <cmath>

namespace station {

void apply_reading(const drivers::counters::CounterReading* rd, SampleRow& r) {
  if (rd == nullptr || !rd->answered) r.flags |= kLatchLost;
  if (rd != nullptr && rd->answered && rd->has_delta) {
    r.net_pulses = rd->net_pulses;
    r.interval_s = rd->interval_s;
    r.rate_dph = rd->rate_dph;
  }
  if (rd != nullptr && rd->temps_c.size() >= 2 && std::isfinite(rd->temps_c[0]) &&
      std::isfinite(rd->temps_c[1])) {
    r.temp_c = rd->temps_c[0];
    r.temp2_c = rd->temps_c[1];
  } else {
    r.flags |= kTempsMissing;
  }
  if (rd != nullptr && rd->status_flags != 0) r.flags |= kBoardFault;
}

}  // namespace station
