// The bytes a ModbusClient taps (wire definitions shared by the client and a session replay):
// ADUs without the transport's framing — no MBAP header, no RTU CRC — the unit id, then the PDU
// as the Modbus Application Protocol v1.1b3 lays it out (section 6, big-endian words). libmodbus
// does not expose its raw frames, so both sides rebuild them with these. No I/O.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "drivers/common/tap.hpp"

namespace station::drivers::modbus {

/// A read request (fc 3 or 4): unit, fc, address, count.
std::vector<std::uint8_t> read_request_adu(int unit, int fc, std::uint16_t addr, int count);
/// A write request: fc 6 for one word (unit, 6, address, value), else fc 16 (unit, 16,
/// address, count, byte count, values).
std::vector<std::uint8_t> write_request_adu(int unit, std::uint16_t addr,
                                            std::span<const std::uint16_t> words);
/// A read reply: unit, fc, byte count, words.
std::vector<std::uint8_t> read_reply_adu(int unit, int fc, std::span<const std::uint16_t> words);

/// errno_bytes / errno_of_bytes: drivers/common/tap.hpp (every transport's error records).
using drivers::errno_bytes;
using drivers::errno_of_bytes;

}  // namespace station::drivers::modbus
