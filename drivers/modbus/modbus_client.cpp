// Modbus client transactions, error translation and tap records.
#include "drivers/modbus/modbus_client.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <variant>

#include "drivers/modbus/modbus_adu.hpp"

namespace station::drivers::modbus {

namespace {

// The one rule for a decoded value: a non-finite one is a protocol error, unless the point is a
// process value that reads NaN when its input fails (Point::nan_on_input_error).
Result<double> checked(const std::string& device, const Point& p, double v) {
  if (!std::isfinite(v) && !p.nan_on_input_error)
    return make_error(ErrorKind::protocol,
                      fmt::format("{} point '{}' is not finite ({})", device, p.name, v));
  return v;
}

}  // namespace

Error translate_modbus_error(int err, const std::string& what) {
  // ETIME: a reply began but was not whole by the exchange's deadline (LibmodbusWire).
  std::string msg = what + ": " +
                    (err == ETIME ? "reply not complete by the deadline (it came too slowly)"
                                  : modbus_strerror(err));
  if (err == ETIMEDOUT || err == EAGAIN || err == ETIME) return make_error(ErrorKind::timeout, msg);
  if (err >= EMBXILFUN && err <= EMBXGTAR) return make_error(ErrorKind::exception, msg);
  if (err >= EMBBADCRC && err <= EMBBADSLAVE) return make_error(ErrorKind::protocol, msg);
  switch (err) {
    case ECONNRESET:
    case ECONNREFUSED:
    case ECONNABORTED:
    case EPIPE:
    case ENOTCONN:
    case EBADF:
    case ENOENT:
    case EHOSTUNREACH:
    case ENETUNREACH:
    case EIO:  // a serial adapter that vanished (USB unplugged, pty master closed)
    case ENXIO:
    case ENODEV:
      return make_error(ErrorKind::disconnected, msg);
    case EINVAL:
      return make_error(ErrorKind::range, msg);
    default:
      return make_error(ErrorKind::io, msg);
  }
}

ModbusClient::ModbusClient(std::string device, Endpoint endpoint, double response_timeout_s)
    : ModbusClient(std::move(device), endpoint, std::make_unique<LibmodbusWire>(endpoint),
                   response_timeout_s) {}

ModbusClient::ModbusClient(std::string device, Endpoint endpoint, std::unique_ptr<ModbusWire> wire,
                           double response_timeout_s)
    : device_(std::move(device)),
      endpoint_(std::move(endpoint)),
      timeout_s_(response_timeout_s),
      wire_(std::move(wire)) {}

ModbusClient::~ModbusClient() = default;

Result<void> ModbusClient::connect() {
  disconnect();
  int rc = 0;
  try {
    rc = wire_->open(timeout_s_);
  } catch (const std::exception& e) {
    state_.connect_failed(device_ + ": " + e.what());
    return make_error(ErrorKind::io, state_.last_error());
  }
  if (rc == -1) {
    int err = errno;
    // A refused or failed connect is always "not connected", whatever errno says.
    auto e = translate_modbus_error(err, device_ + " connect " + to_string(endpoint_));
    if (e.kind != ErrorKind::timeout) e.kind = ErrorKind::disconnected;
    tap(TapDirection::event, "error", errno_bytes(err), e.message);
    state_.connect_failed(e.message);
    return e;
  }
  state_.connect_succeeded();
  unit_answered_ = false;
  tap(TapDirection::event, "connect", {}, to_string(endpoint_));
  return {};
}

void ModbusClient::disconnect() {
  if (state_.connected()) tap(TapDirection::event, "disconnect", {}, to_string(endpoint_));
  wire_->close();
  state_.closed();
}

Result<void> ModbusClient::ensure_connected() {
  return state_.ensure(device_, [this] { return connect(); });
}

// What a failure says about the unit id: a gateway's exception names the unit nothing answered;
// a timeout before the unit ever answered on this link is a wrong address or no unit at all (a
// unit is silent for another address: Modbus over Serial Line v1.02 §2.2, docs/DEVICES.md).
std::string ModbusClient::unit_hint(int err, int unit) const {
  if (err == EMBXGTAR || err == EMBXGPATH)
    return fmt::format(
        " (a gateway's exception: no device answered unit {} behind it; check "
        "unit_id)",
        unit);
  if ((err == ETIMEDOUT || err == EAGAIN) && !unit_answered_)
    return fmt::format(
        " (unit {} has not answered since the link opened, {:.2f} s each: check "
        "unit_id against the unit's Modbus address)",
        unit, timeout_s_);
  return {};
}

Error ModbusClient::fail(int err, int unit, const std::string& what) {
  Error e = translate_modbus_error(err, device_ + " " + what);
  e.message += unit_hint(err, unit);
  // An exception reply from the unit itself is an answer (not one from a gateway in front).
  if (e.kind == ErrorKind::exception && err != EMBXGTAR && err != EMBXGPATH) unit_answered_ = true;
  const bool reopen = link_.must_reopen(e.kind, std::holds_alternative<TcpEndpoint>(endpoint_));
  if (reopen && link_.stale_timeouts() > 0)
    e.message += fmt::format(" ({} timeouts in a row: reconnecting)", link_.stale_timeouts());
  tap(TapDirection::event, "error", errno_bytes(err), e.message);
  if (reopen) {
    disconnect();  // reconnect on the next call
  } else if (e.kind == ErrorKind::timeout || e.kind == ErrorKind::protocol) {
    // Discard late or partial bytes so the next reply is not misread as this one's.
    if (state_.connected()) wire_->flush();
  }
  return e;
}

Result<std::vector<std::uint16_t>> ModbusClient::read_registers(FunctionCode fc, int unit,
                                                                std::uint16_t addr, int count) {
  if (auto c = ensure_connected(); !c) return c.error();
  int code = static_cast<int>(fc);
  tap_read_request(fc, unit, addr, count);
  std::vector<std::uint16_t> words(static_cast<std::size_t>(count));
  int rc = wire_->read(fc, unit, addr, count, words.data());
  if (rc == -1)
    return fail(errno, unit, fmt::format("read fc={} addr={} count={}", code, addr, count));
  if (rc != count)
    return fail(EMBBADDATA, unit,
                fmt::format("read addr={}: {} registers, wanted {}", addr, rc, count));
  read_answered(fc, unit, addr, words);
  return words;
}

void ModbusClient::tap_read_request(FunctionCode fc, int unit, std::uint16_t addr, int count) {
  const int code = static_cast<int>(fc);
  tap(TapDirection::tx, "modbus-read", read_request_adu(unit, code, addr, count),
      fmt::format("unit={} fc={} addr={} count={}", unit, code, addr, count));
}

// A reply read: the unit answered, the link is fresh, the tap has it.
void ModbusClient::read_answered(FunctionCode fc, int unit, std::uint16_t addr,
                                 std::span<const std::uint16_t> words) {
  link_.answered();
  unit_answered_ = true;
  tap(TapDirection::rx, "modbus-read", read_reply_adu(unit, static_cast<int>(fc), words),
      fmt::format("unit={} addr={}", unit, addr));
}

// The tap has each request and its outcome in the order read_registers would have made them
// (a session replays the same whether it was read in a batch or not); the requests after a failed
// one were sent and are abandoned, not recorded.
Result<std::vector<std::vector<std::uint16_t>>> ModbusClient::read_group(
    std::span<const ReadBlock> group) {
  std::vector<std::vector<std::uint16_t>> words(group.size());
  if (group.size() == 1) {
    auto one = read_registers(group[0].function, group[0].unit_id, group[0].start, group[0].count);
    if (!one) return one.error();
    words[0] = std::move(one).value();
    return words;
  }
  if (auto c = ensure_connected(); !c) return c.error();
  std::vector<ReadRequest> requests;
  for (std::size_t i = 0; i < group.size(); ++i) {
    const auto& b = group[i];
    words[i].resize(static_cast<std::size_t>(b.count));
    requests.push_back({b.function, b.unit_id, b.start, b.count, words[i].data()});
  }
  const auto done = static_cast<std::size_t>(wire_->read_batch(requests));
  const int err = errno;
  for (std::size_t i = 0; i < done; ++i) {
    tap_read_request(group[i].function, group[i].unit_id, group[i].start, group[i].count);
    read_answered(group[i].function, group[i].unit_id, group[i].start, words[i]);
  }
  if (done == group.size()) return words;
  const auto& b = group[done];
  tap_read_request(b.function, b.unit_id, b.start, b.count);
  return fail(
      err, b.unit_id,
      fmt::format("read fc={} addr={} count={}", static_cast<int>(b.function), b.start, b.count));
}

Result<void> ModbusClient::write_registers(int unit, std::uint16_t addr,
                                           std::span<const std::uint16_t> words) {
  if (auto c = ensure_connected(); !c) return c.error();
  int n = static_cast<int>(words.size());
  int code = n == 1 ? 6 : 16;
  tap(TapDirection::tx, "modbus-write", write_request_adu(unit, addr, words),
      fmt::format("unit={} fc={} addr={} count={}", unit, code, addr, n));
  int rc = wire_->write(unit, addr, words);
  if (rc == -1)
    return fail(errno, unit, fmt::format("write fc={} addr={} count={}", code, addr, n));
  link_.answered();
  unit_answered_ = true;
  tap(TapDirection::rx, "modbus-write",
      n == 1 ? write_request_adu(unit, addr, words) : read_request_adu(unit, code, addr, n),
      fmt::format("unit={} addr={} ok", unit, addr));
  return {};
}

Result<double> ModbusClient::read(const Point& p) {
  auto words = read_registers(p.function, p.unit_id, p.pdu_address(), p.word_count());
  if (!words) return words.error();
  return checked(device_, p, decode_point(p, words.value().data()));
}

Result<void> ModbusClient::write(const Point& p, double value) {
  if (p.access != Access::rw || p.function != FunctionCode::holding)
    return make_error(ErrorKind::range, device_ + " point '" + p.name + "' is read-only");
  auto words = encode_point(p, value);
  if (!words)
    return make_error(ErrorKind::range,
                      fmt::format("{} point '{}': {} does not fit", device_, p.name, value));
  return write_registers(p.unit_id, p.pdu_address(),
                         std::span<const std::uint16_t>(words->data(), p.word_count()));
}

void ModbusClient::tap(TapDirection dir, const char* kind, std::vector<std::uint8_t> bytes,
                       std::string detail) {
  if (tap_ == nullptr) return;
  TapRecord r{tap_wall_time_s(), device_, dir, kind, std::move(bytes), std::move(detail)};
  tap_->on_exchange(r);
}

Result<std::vector<double>> ModbusClient::read_points(std::span<const Point> points,
                                                      std::span<const ReadBlock> plan) {
  std::vector<double> v(points.size());
  const auto step = static_cast<std::size_t>(pipeline_);
  for (std::size_t first = 0; first < plan.size(); first += step) {
    const auto group = plan.subspan(first, std::min(step, plan.size() - first));
    auto words = read_group(group);
    if (!words) return words.error();
    for (std::size_t k = 0; k < group.size(); ++k) {
      for (std::size_t i : group[k].points) {
        const Point& p = points[i];
        const std::uint16_t* at = words.value()[k].data() + (p.pdu_address() - group[k].start);
        auto value = checked(device_, p, decode_point(p, at));
        if (!value) return value.error();
        v[i] = value.value();
      }
    }
  }
  return v;
}

}  // namespace station::drivers::modbus
