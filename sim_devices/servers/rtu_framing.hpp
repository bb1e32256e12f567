// Modbus RTU framing as a serial device does it (Modbus over Serial Line v1.02, 2.5.1): a frame
// ends at a silence and carries a CRC-16; which unit id a device answers is unit_address.hpp.
#pragma once

#include <cstdint>
#include <span>

namespace station::sim {

/// CRC-16/MODBUS of `bytes` (polynomial 0xA001 reflected, initial 0xFFFF; spec 6.2.2).
std::uint16_t modbus_crc16(std::span<const std::uint8_t> bytes);

/// Reads one frame from `fd`, which poll() found readable: bytes until `silence_ms` pass with
/// none (the spec's 3.5-character gap) or `cap` bytes. Returns the bytes read (0 if none).
int read_rtu_frame(int fd, std::uint8_t* buf, int cap, int silence_ms);

/// True when `frame` is a whole RTU frame: unit id, function code and CRC at least, its CRC
/// right. A damaged frame gets no answer at all (spec 2.5.1.2).
bool rtu_frame_ok(std::span<const std::uint8_t> frame);

}  // namespace station::sim
