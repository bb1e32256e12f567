// Fuzz target: register maps as a config can shape them (drivers/modbus/map_overrides.*), the
// block-read planner (read_plan.*) and the point codec (register_map.hpp).
// Input: byte 0 picks a preset, byte 1 the read gap; then 8-byte point overrides; the rest are
// register words a device might answer.
// Properties: no crash or UB; every planned block is a legal Modbus read (1..125 registers inside
// the 0..65535 address space) of one unit and table that holds each of its points whole; every
// point is in exactly one block; a decoded finite value encodes back to the same words.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/modbus/map_overrides.hpp"
#include "drivers/modbus/read_plan.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "fuzz_check.hpp"

namespace mb = station::drivers::modbus;
using station::fuzz::check;

namespace {

struct Reader {
  const std::uint8_t* p;
  std::size_t n;
  bool has(std::size_t k) const { return n >= k; }
  std::uint8_t u8() { return has(1) ? (--n, *p++) : 0; }
  std::uint16_t u16() {
    const int hi = u8();  // two statements: the order of the reads matters
    return static_cast<std::uint16_t>(hi << 8 | u8());
  }
};

mb::RegisterMap preset(std::uint8_t which) {
  switch (which % 3) {
    case 0:
      return station::drivers::chamber_map::generic_plc();
    case 1:
      return station::drivers::chamber_map::generic_plc_float();
    default:
      return station::drivers::turntable_map::generic_plc();
  }
}

// One override from 8 bytes: point index, address, flag bits, unit id, scale choice.
mb::PointOverride override_from(Reader& in, const mb::RegisterMap& map) {
  static constexpr double kScales[] = {1.0, 0.1, 0.01, 10.0, -0.5, 1e-30, 1e30, 0.0};
  mb::PointOverride o;
  auto it = map.points().begin();
  std::advance(it, in.u8() % map.points().size());
  o.name = it->first;
  const std::uint16_t address = in.u16();
  const std::uint8_t flags = in.u8();
  const std::uint8_t unit = in.u8();
  const std::uint8_t scale = in.u8();
  in.u8();
  in.u8();
  if (flags & 0x01) o.address = address;
  if (flags & 0x02) o.type = static_cast<mb::PointType>((flags >> 2) % 3);
  if (flags & 0x10) o.function = flags & 0x20 ? mb::FunctionCode::input : mb::FunctionCode::holding;
  if (flags & 0x40) o.one_based = (flags & 0x80) != 0;
  if (unit & 0x80) o.unit_id = unit & 0x7F;
  if (scale & 0x80) o.scale = kScales[scale % 8];
  o.order = scale & 0x40 ? mb::WordOrder::cdab : mb::WordOrder::abcd;
  return o;
}

void check_plan(const std::vector<mb::Point>& pts, const std::vector<mb::ReadBlock>& plan) {
  std::vector<int> seen(pts.size(), 0);
  for (const auto& b : plan) {
    check(b.count >= 1 && b.count <= mb::kMaxReadRegisters, "block of " + std::to_string(b.count));
    check(b.start + b.count <= 65536,
          "block " + std::to_string(b.start) + "+" + std::to_string(b.count) + " past 65535");
    for (std::size_t i : b.points) {
      const auto& p = pts.at(i);
      ++seen[i];
      check(p.unit_id == b.unit_id && p.function == b.function, "point in a foreign block");
      check(p.pdu_address() >= b.start && p.pdu_address() + p.word_count() <= b.start + b.count,
            "point '" + p.name + "' not whole inside its block");
    }
  }
  for (int s : seen) check(s == 1, "a point planned " + std::to_string(s) + " times");
}

void check_codec(const mb::Point& p, const std::uint16_t* words) {
  const double v = mb::decode_point(p, words);
  if (!std::isfinite(v) || std::fabs(v / p.scale) > 3.4e38) return;
  const auto back = mb::encode_point(p, v);
  check(back.has_value(), "decoded value of '" + p.name + "' does not encode");
  check(mb::decode_point(p, back->data()) == v, "'" + p.name + "' does not round-trip");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in{data, size};
  mb::RegisterMap map = preset(in.u8());
  const int gap = static_cast<std::int8_t>(in.u8());
  for (int k = 0; k < 6 && in.has(8); ++k) {
    try {
      mb::apply_overrides(map, {override_from(in, map)});
    } catch (const std::invalid_argument&) {
      // Rejected as a config error would be: the map stays as it was.
    }
  }
  std::vector<mb::Point> pts;
  for (const auto& [name, p] : map.points()) pts.push_back(p);
  const auto plan = mb::plan_reads(pts, gap);
  check_plan(pts, plan);
  for (const auto& b : plan) {
    std::vector<std::uint16_t> words(static_cast<std::size_t>(b.count));
    for (auto& w : words) w = in.u16();
    for (std::size_t i : b.points)
      check_codec(pts[i], words.data() + (pts[i].pdu_address() - b.start));
  }
  return 0;
}
