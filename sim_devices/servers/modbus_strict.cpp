// request_exception: a register-by-register check of a request PDU against a register map.
#include "sim_devices/servers/modbus_strict.hpp"

#include <array>

namespace station::sim {
namespace mb = drivers::modbus;

namespace {

constexpr std::uint8_t kReadHolding = 0x03;
constexpr std::uint8_t kReadInput = 0x04;
constexpr std::uint8_t kWriteSingle = 0x06;
constexpr std::uint8_t kWriteMultiple = 0x10;
// Quantity limits of spec 6.3/6.4 (reads) and 6.12 (write multiple).
constexpr int kMaxReadCount = 125;
constexpr int kMaxWriteCount = 123;

int be16(std::span<const std::uint8_t> pdu, std::size_t at) {
  return pdu[at] << 8 | pdu[at + 1];
}

// The point of `table` that occupies register `reg`, or nullptr.
const mb::Point* point_at(const mb::RegisterMap& map, mb::FunctionCode table, int reg) {
  for (const auto& [name, p] : map.points()) {
    if (p.function == table && reg >= p.pdu_address() && reg < p.pdu_address() + p.word_count())
      return &p;
  }
  return nullptr;
}

std::uint8_t read_exception(const mb::RegisterMap& map, mb::FunctionCode table, int addr,
                            int count) {
  if (count < 1 || count > kMaxReadCount) return kIllegalDataValue;
  for (int r = addr; r < addr + count; ++r) {
    if (point_at(map, table, r) == nullptr) return kIllegalDataAddress;
  }
  return 0;
}

std::uint8_t write_exception(const mb::RegisterMap& map, int addr, int count) {
  for (int r = addr; r < addr + count; ++r) {
    const mb::Point* p = point_at(map, mb::FunctionCode::holding, r);
    if (p == nullptr || p->access != mb::Access::rw) return kIllegalDataAddress;
    // A write may not cut a point in two (half of a float32 is no value at all).
    if (p->pdu_address() < addr || p->pdu_address() + p->word_count() > addr + count)
      return kIllegalDataAddress;
  }
  return 0;
}

}  // namespace

std::uint8_t request_exception(const mb::RegisterMap& map, std::span<const std::uint8_t> pdu) {
  if (pdu.empty()) return kIllegalFunction;
  const std::uint8_t fc = pdu[0];
  if (fc != kReadHolding && fc != kReadInput && fc != kWriteSingle && fc != kWriteMultiple)
    return kIllegalFunction;
  if (pdu.size() < 5) return kIllegalDataValue;
  const int addr = be16(pdu, 1);
  const int count = be16(pdu, 3);  // the value itself for FC 6
  switch (fc) {
    case kReadHolding:
      return read_exception(map, mb::FunctionCode::holding, addr, count);
    case kReadInput:
      return read_exception(map, mb::FunctionCode::input, addr, count);
    case kWriteSingle:
      return write_exception(map, addr, 1);
    default:
      break;
  }
  if (count < 1 || count > kMaxWriteCount || pdu.size() < 6 || pdu[5] != 2 * count ||
      pdu.size() < 6 + 2 * static_cast<std::size_t>(count))
    return kIllegalDataValue;
  return write_exception(map, addr, count);
}

std::optional<RegisterWrite> parse_write(std::span<const std::uint8_t> pdu) {
  if (pdu.size() >= 5 && pdu[0] == kWriteSingle)
    return RegisterWrite{static_cast<std::uint16_t>(be16(pdu, 1)), pdu.subspan(3, 2)};
  if (pdu.size() < 6 || pdu[0] != kWriteMultiple) return std::nullopt;
  const int count = be16(pdu, 3);
  if (count < 1 || pdu[5] != 2 * count || pdu.size() < 6 + 2 * static_cast<std::size_t>(count))
    return std::nullopt;
  return RegisterWrite{static_cast<std::uint16_t>(be16(pdu, 1)),
                       pdu.subspan(6, 2 * static_cast<std::size_t>(count))};
}

std::optional<double> RegisterWrite::value_of(const mb::Point& p) const {
  const int first = p.pdu_address() - address;
  if (p.function != mb::FunctionCode::holding || first < 0 || first + p.word_count() > count())
    return std::nullopt;
  const std::array<std::uint16_t, 2> w{word(first),
                                       p.word_count() == 2 ? word(first + 1) : std::uint16_t{0}};
  return mb::decode_point(p, w.data());
}

}  // namespace station::sim
