// Answering a ModbusClient from a recording (see replay_modbus.hpp).
#include "station/session/replay_modbus.hpp"

#include <fmt/format.h>

#include <cerrno>

#include "drivers/modbus/modbus_adu.hpp"
#include "station/session/session_recorder.hpp"

namespace station {
namespace {

namespace mb = station::drivers::modbus;

std::string describe(const SessionLogLine& l) {
  return fmt::format("line {}: {} {} {}", l.line_no, l.direction, l.kind, hex_field(l.bytes));
}

}  // namespace

ReplayDivergence::ReplayDivergence(std::string d, std::string rec, std::string ask, double t)
    : std::runtime_error(fmt::format("{}: the recording has {}, the replay asked {}", d, rec, ask)),
      device(std::move(d)),
      recorded(std::move(rec)),
      asked(std::move(ask)),
      t_s(t) {}

RecordedModbusWire::RecordedModbusWire(std::string device, std::vector<SessionLogLine> lines)
    : RecordedModbusWire(std::move(device), ReplayFeed<SessionLogLine>(std::move(lines))) {}

RecordedModbusWire::RecordedModbusWire(std::string device, ReplayFeed<SessionLogLine> lines)
    : device_(std::move(device)), lines_(std::move(lines)) {}

const SessionLogLine& RecordedModbusWire::expect(const char* direction, const char* kind,
                                                 const std::vector<std::uint8_t>* bytes,
                                                 const Asked& asked) {
  const SessionLogLine* l = peek();
  if (l == nullptr) throw ReplayDivergence(device_, "no more exchanges", asked(), 0);
  if (l->direction != direction || l->kind != kind || (bytes != nullptr && l->bytes != *bytes))
    throw ReplayDivergence(device_, describe(*l), asked(), l->t_s);
  return lines_.take();
}

const std::vector<std::uint8_t>* RecordedModbusWire::reply(const char* kind, const Asked& asked) {
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "error" && l->bytes.size() == 4) {
    const auto& e = lines_.take();
    errno = mb::errno_of_bytes(std::span<const std::uint8_t, 4>(e.bytes.data(), 4));
    return nullptr;
  }
  return &expect("rx", kind, nullptr, [&asked] { return "the reply to " + asked(); }).bytes;
}

int RecordedModbusWire::open(double) {
  const Asked asked = [] { return std::string("connect"); };
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "error" && l->bytes.size() == 4) {
    (void)reply("connect", asked);
    return -1;
  }
  expect("event", "connect", nullptr, asked);
  return 0;
}

void RecordedModbusWire::close() {
  const SessionLogLine* l = peek();
  if (l != nullptr && l->direction == "event" && l->kind == "disconnect") (void)lines_.take();
}

// The request's description is built only for a divergence: a long replay asks ~10^6 times.
int RecordedModbusWire::read(mb::FunctionCode fc, int unit, std::uint16_t addr, int count,
                             std::uint16_t* dest) {
  const auto req = mb::read_request_adu(unit, static_cast<int>(fc), addr, count);
  const Asked asked = [&req] { return "tx modbus-read " + hex_field(req); };
  expect("tx", "modbus-read", &req, asked);
  const auto* rx = reply("modbus-read", asked);
  if (rx == nullptr) return -1;
  // unit, fc, byte count, registers (big-endian).
  const auto& r = *rx;
  if (r.size() < 3 || r.size() != 3u + r[2] || r[2] % 2 != 0)
    throw ReplayDivergence(device_, "a malformed reply " + hex_field(r), asked(), 0);
  const int n = r[2] / 2;
  for (int i = 0; i < n && i < count; ++i)
    dest[i] = static_cast<std::uint16_t>(r[3 + 2 * i] << 8 | r[4 + 2 * i]);
  return n;
}

int RecordedModbusWire::write(int unit, std::uint16_t addr, std::span<const std::uint16_t> words) {
  const auto req = mb::write_request_adu(unit, addr, words);
  const Asked asked = [&req] { return "tx modbus-write " + hex_field(req); };
  expect("tx", "modbus-write", &req, asked);
  if (reply("modbus-write", asked) == nullptr) return -1;
  return static_cast<int>(words.size());
}

}  // namespace station
