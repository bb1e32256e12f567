// Answering a ModbusClient from a recording (see replay_modbus.hpp).
#include "station/session/replay_modbus.hpp"

#include <fmt/format.h>

#include <cerrno>

namespace station {
namespace {

namespace mb = station::drivers::modbus;

std::string hex(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  for (auto b : bytes) out += fmt::format("{:02x}", b);
  return out.empty() ? "-" : out;
}

std::string describe(const SessionLogLine& l) {
  return fmt::format("line {}: {} {} {}", l.line_no, l.direction, l.kind, hex(l.bytes));
}

void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
}

}  // namespace

ReplayDivergence::ReplayDivergence(std::string d, std::string rec, std::string ask, double t)
    : std::runtime_error(fmt::format("{}: the recording has {}, the replay asked {}", d, rec, ask)),
      device(std::move(d)),
      recorded(std::move(rec)),
      asked(std::move(ask)),
      t_s(t) {}

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

RecordedModbusWire::RecordedModbusWire(std::string device, std::vector<SessionLogLine> lines)
    : device_(std::move(device)), lines_(std::move(lines)) {}

const SessionLogLine& RecordedModbusWire::expect(const char* direction, const char* kind,
                                                 const std::vector<std::uint8_t>* bytes,
                                                 const std::string& asked) {
  const SessionLogLine* l = peek();
  if (l == nullptr) throw ReplayDivergence(device_, "no more exchanges", asked, 0);
  if (l->direction != direction || l->kind != kind || (bytes != nullptr && l->bytes != *bytes))
    throw ReplayDivergence(device_, describe(*l), asked, l->t_s);
  ++next_;
  return *l;
}

bool RecordedModbusWire::reply(const char* kind, std::vector<std::uint8_t>& bytes,
                               const std::string& asked) {
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "error" && l->bytes.size() == 4) {
    ++next_;
    errno = static_cast<int>(static_cast<std::uint32_t>(l->bytes[0]) << 24 |
                             static_cast<std::uint32_t>(l->bytes[1]) << 16 |
                             static_cast<std::uint32_t>(l->bytes[2]) << 8 | l->bytes[3]);
    return false;
  }
  bytes = expect("rx", kind, nullptr, "the reply to " + asked).bytes;
  return true;
}

int RecordedModbusWire::open(double) {
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "error" && l->bytes.size() == 4) {
    std::vector<std::uint8_t> unused;
    (void)reply("connect", unused, "connect");
    return -1;
  }
  expect("event", "connect", nullptr, "connect");
  return 0;
}

void RecordedModbusWire::close() {
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "disconnect") ++next_;
}

int RecordedModbusWire::read(mb::FunctionCode fc, int unit, std::uint16_t addr, int count,
                             std::uint16_t* dest) {
  const auto req = read_request_adu(unit, static_cast<int>(fc), addr, count);
  const std::string asked = "tx modbus-read " + hex(req);
  expect("tx", "modbus-read", &req, asked);
  std::vector<std::uint8_t> rx;
  if (!reply("modbus-read", rx, asked)) return -1;
  // unit, fc, byte count, registers (big-endian).
  if (rx.size() < 3 || rx.size() != 3u + rx[2] || rx[2] % 2 != 0)
    throw ReplayDivergence(device_, "a malformed reply " + hex(rx), asked, 0);
  const int n = rx[2] / 2;
  for (int i = 0; i < n && i < count; ++i)
    dest[i] = static_cast<std::uint16_t>(rx[3 + 2 * i] << 8 | rx[4 + 2 * i]);
  return n;
}

int RecordedModbusWire::write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) {
  const auto req = write_request_adu(unit, addr, words);
  const std::string asked = "tx modbus-write " + hex(req);
  expect("tx", "modbus-write", &req, asked);
  std::vector<std::uint8_t> rx;
  if (!reply("modbus-write", rx, asked)) return -1;
  return static_cast<int>(words.size());
}

}  // namespace station
