// The one path from a counter board's reading to the gyro part of a stored sample, run by the
// sequencer and by `station replay` alike.
#pragma once

#include "drivers/counters/counter_boards.hpp"
#include "station/store/store.hpp"

namespace station {

/// Fills the gyro part of `row` from `reading` (nullptr: the board is not in this tick's
/// answers): pulses, interval and rate only when the latch is chained to a previous good one;
/// sensor A and B only when both are finite; flags kLatchLost, kTempsMissing, kBoardFault.
void apply_reading(const drivers::counters::CounterReading* reading, SampleRow& row);

}  // namespace station
