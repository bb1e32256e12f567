// Tapped Modbus ADUs (see modbus_adu.hpp).
#include "drivers/modbus/modbus_adu.hpp"

namespace station::drivers::modbus {
namespace {

void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
}

}  // namespace

std::vector<std::uint8_t> read_request_adu(int unit, int fc, std::uint16_t addr, int count) {
  std::vector<std::uint8_t> out{static_cast<std::uint8_t>(unit), static_cast<std::uint8_t>(fc)};
  put_u16(out, addr);
  put_u16(out, static_cast<std::uint16_t>(count));
  return out;
}

std::vector<std::uint8_t> write_request_adu(int unit, std::uint16_t addr,
                                            std::span<const std::uint16_t> words) {
  const bool single = words.size() == 1;
  std::vector<std::uint8_t> out{static_cast<std::uint8_t>(unit),
                                static_cast<std::uint8_t>(single ? 6 : 16)};
  put_u16(out, addr);
  if (!single) {
    put_u16(out, static_cast<std::uint16_t>(words.size()));
    out.push_back(static_cast<std::uint8_t>(2 * words.size()));
  }
  for (auto w : words) put_u16(out, w);
  return out;
}

std::vector<std::uint8_t> read_reply_adu(int unit, int fc, std::span<const std::uint16_t> words) {
  std::vector<std::uint8_t> out{static_cast<std::uint8_t>(unit), static_cast<std::uint8_t>(fc),
                                static_cast<std::uint8_t>(2 * words.size())};
  for (auto w : words) put_u16(out, w);
  return out;
}

}  // namespace station::drivers::modbus
