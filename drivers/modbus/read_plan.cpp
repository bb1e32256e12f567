// plan_reads: sort points by (unit, function, address) and merge neighbours into blocks.
#include "drivers/modbus/read_plan.hpp"

#include <algorithm>
#include <numeric>
#include <tuple>

namespace station::drivers::modbus {

std::vector<ReadBlock> plan_reads(std::span<const Point> points, int max_gap_registers) {
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  auto key = [&points](std::size_t i) {
    const Point& p = points[i];
    return std::tuple(p.unit_id, static_cast<int>(p.function), p.pdu_address());
  };
  std::stable_sort(order.begin(), order.end(),
                   [&key](std::size_t a, std::size_t b) { return key(a) < key(b); });
  std::vector<ReadBlock> blocks;
  for (std::size_t i : order) {
    const Point& p = points[i];
    const int addr = p.pdu_address();
    const int end = addr + p.word_count();
    if (!blocks.empty() && max_gap_registers >= 0) {
      ReadBlock& b = blocks.back();
      const int b_end = b.start + b.count;
      const bool same_table = b.unit_id == p.unit_id && b.function == p.function;
      if (same_table && addr - b_end <= max_gap_registers &&
          std::max(end, b_end) - b.start <= kMaxReadRegisters) {
        b.count = std::max(end, b_end) - b.start;
        b.points.push_back(i);
        continue;
      }
    }
    blocks.push_back({p.unit_id, p.function, p.pdu_address(), p.word_count(), {i}});
  }
  return blocks;
}

std::vector<ReadBlock> plan_each(std::span<const Point> points) {
  std::vector<ReadBlock> blocks;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    blocks.push_back({p.unit_id, p.function, p.pdu_address(), p.word_count(), {i}});
  }
  return blocks;
}

}  // namespace station::drivers::modbus
