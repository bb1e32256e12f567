// Coalescing of register-map point reads into block reads: points of one unit and function code
// whose registers lie close together are fetched in one transaction and decoded from the block.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "drivers/modbus/register_map.hpp"

namespace station::drivers::modbus {

/// Most registers one read may ask for (Modbus Application Protocol v1.1b3, 6.3/6.4: 1..125).
inline constexpr int kMaxReadRegisters = 125;

/// One block read covering some points: registers [start, start + count) of one unit and table.
struct ReadBlock {
  int unit_id = 1;
  FunctionCode function = FunctionCode::holding;
  std::uint16_t start = 0;          ///< first PDU address
  int count = 0;                    ///< registers, 1..kMaxReadRegisters
  std::vector<std::size_t> points;  ///< indices into the planned points, by address
};

/// Groups `points` into the fewest block reads such that points share a block only with the same
/// unit and function code, at most `max_gap_registers` unread registers between neighbours, and
/// no block exceeds kMaxReadRegisters. max_gap_registers = 0 merges only adjacent points; < 0
/// gives one block per point. Blocks come out sorted by unit, function, address. No I/O.
std::vector<ReadBlock> plan_reads(std::span<const Point> points, int max_gap_registers);
/// One block per point, in the order of `points`: the reads of reading each point by itself (the
/// same requests in the same order), for a client that may have them on the wire together. No I/O.
std::vector<ReadBlock> plan_each(std::span<const Point> points);

}  // namespace station::drivers::modbus
