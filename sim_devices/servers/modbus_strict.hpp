// What a strict Modbus device owes a request it cannot serve: the exception code of the Modbus
// Application Protocol v1.1b3 (section 7), decided from the device's register map alone. No I/O.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "drivers/modbus/register_map.hpp"

namespace station::sim {

/// Modbus exception codes (Modbus Application Protocol v1.1b3, section 7).
inline constexpr std::uint8_t kIllegalFunction = 0x01;
inline constexpr std::uint8_t kIllegalDataAddress = 0x02;
inline constexpr std::uint8_t kIllegalDataValue = 0x03;

/// The exception a device with `map` answers to the request PDU `pdu` (function code first, no
/// address/CRC framing), or 0 when it serves it. Functions other than 3, 4, 6, 16: 01. A bad
/// quantity or byte count: 03. A read of any register that no point of that table occupies, a
/// write to a register that is not a read-write holding point, or a write that covers only part
/// of a point: 02 (spec 6.3, 6.4, 6.6, 6.12).
std::uint8_t request_exception(const drivers::modbus::RegisterMap& map,
                               std::span<const std::uint8_t> pdu);

/// A decoded register write: first PDU address and the words written (FC 6 or 16 only).
struct RegisterWrite {
  std::uint16_t address = 0;
  std::span<const std::uint8_t> words_be;  ///< 2 bytes per register, big-endian, as on the wire

  /// Number of registers written.
  int count() const { return static_cast<int>(words_be.size() / 2); }
  /// Word i, host order.
  std::uint16_t word(int i) const {
    return static_cast<std::uint16_t>(words_be[2 * i] << 8 | words_be[2 * i + 1]);
  }
  /// Engineering value written to point `p` when the write covers all of its words.
  std::optional<double> value_of(const drivers::modbus::Point& p) const;
};

/// The write a well-formed FC 6 or FC 16 request PDU carries; nullopt for anything else.
std::optional<RegisterWrite> parse_write(std::span<const std::uint8_t> pdu);

}  // namespace station::sim
