// The session's device logs: dispatch by record kind, one line per exchange.
#include "station/session/session_recorder.hpp"

#include <fmt/format.h>

#include <cstring>
#include <filesystem>

#include "drivers/can/candump_log.hpp"
#include "station/common/input_error.hpp"

namespace station {
namespace {

namespace dr = station::drivers;

std::ofstream open_log(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::app);
  if (!out) throw InputError(fmt::format("{}: cannot write the session log", path.string()));
  return out;
}

const char* direction_name(dr::TapDirection d) {
  switch (d) {
    case dr::TapDirection::tx:
      return "tx";
    case dr::TapDirection::rx:
      return "rx";
    case dr::TapDirection::event:
      return "event";
  }
  return "?";
}

}  // namespace

std::string hex_field(const std::vector<std::uint8_t>& bytes) {
  std::string hex;
  for (const auto b : bytes) hex += fmt::format("{:02x}", b);
  return hex.empty() ? "-" : hex;
}

std::string format_session_line(const dr::TapRecord& record, double t_s) {
  const std::string hex = hex_field(record.bytes);
  std::string detail = record.detail;
  for (auto& c : detail)
    if (c == '\n' || c == '\r') c = ' ';  // one exchange, one line
  return fmt::format("{:.6f} {} {} {} {} {}", t_s, record.device, direction_name(record.direction),
                     record.kind, hex, detail);
}

SessionRecorder::SessionRecorder(const std::string& dir, Stamp stamp) : stamp_(std::move(stamp)) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw InputError(fmt::format("{}: cannot create the session directory: {}", dir, ec.message()));
  const std::filesystem::path d(dir);
  can_ = open_log(d / "can.log");
  modbus_ = open_log(d / "modbus.log");
  ascii_ = open_log(d / "ascii.log");
  gpio_ = open_log(d / "gpio.log");
}

void SessionRecorder::on_exchange(const dr::TapRecord& record) noexcept {
  if (paused_) return;
  try {
    const double t_s = stamp_ ? stamp_(record) : record.wall_time_s;
    const std::lock_guard lock(mutex_);
    if (record.kind == "can") {
      write_can(record, t_s);
    } else if (record.kind.starts_with("ascii")) {
      write_line(ascii_, record, t_s);  // line devices: exchanges and their link's events
    } else if (record.kind.starts_with("gpio")) {
      write_line(gpio_, record, t_s);
    } else if (record.kind.starts_with("modbus") || record.device != "can") {
      // Modbus exchanges and the Modbus clients' events (error, connect, disconnect). The CAN
      // transport's own events have no place in a candump log: outages are in the run's events.
      write_line(modbus_, record, t_s);
    }
  } catch (...) {
    // A tap must never throw into a transport: a lost log line is preferable.
  }
}

void SessionRecorder::write_can(const dr::TapRecord& record, double t_s) {
  if (record.bytes.size() != sizeof(can_frame)) return;
  dr::can::CandumpRecord r;
  std::memcpy(&r.frame, record.bytes.data(), sizeof r.frame);
  r.time_sec = static_cast<std::int64_t>(t_s);
  const double usec = (t_s - static_cast<double>(r.time_sec)) * 1e6;
  r.time_usec = static_cast<std::uint32_t>(usec < 0 ? 0 : usec > 999999 ? 999999 : usec);
  r.interface = "can0";
  can_ << dr::can::format_candump_line(r) << '\n';
}

void SessionRecorder::write_line(std::ofstream& out, const dr::TapRecord& record, double t_s) {
  out << format_session_line(record, t_s) << '\n';
}

void SessionRecorder::flush() {
  const std::lock_guard lock(mutex_);
  can_.flush();
  modbus_.flush();
  ascii_.flush();
  gpio_.flush();
}

}  // namespace station
