// Fuzz target: Modbus replies from a hostile or broken device, through the whole client path:
// libmodbus's reply checks, ModbusClient's error translation and block decoding, and the
// register maps of ModbusChamber (Watlow F4 or F4T) and ModbusTurntable.
// A fake device on 127.0.0.1 answers each request with the next reply of the input, framed with
// a correct MBAP header (so no reply waits for bytes that never come, unless the PDU itself
// claims more). Input: byte 0 picks the chamber map and whether a setpoint is commanded; then
// replies, each [flags][length][PDU bytes]; when they run out the device answers exception 04.
// Property: no crash, UB or hang; a successful read holds only finite values (air NaN only with
// the sensor-break alarm), a mode inside its enum; and a call whose transactions each have a
// 5 ms timeout returns within kCallBoundS (at most 7 transactions: 35 ms of timeouts, the rest
// is slack for a loaded machine), the daemon's "every I/O has a timeout".
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/generic_plc/modbus_turntable.hpp"
#include "fuzz_check.hpp"

namespace dr = station::drivers;
namespace mb = station::drivers::modbus;
using station::fuzz::check;

namespace {

constexpr double kTimeoutS = 0.005;
constexpr double kCallBoundS = 0.4;
constexpr std::uint8_t kFlagWrongTid = 0x01;
constexpr std::uint8_t kFlagWrongUnit = 0x02;
constexpr std::uint8_t kFlagWrongProtocol = 0x04;
constexpr std::uint8_t kFlagHangUp = 0x08;

struct Reply {
  std::uint8_t flags = 0;
  std::vector<std::uint8_t> pdu;
};

// The device: a thread serving one connection at a time, replies set per input.
class FakeDevice {
 public:
  FakeDevice() {
    listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        listen(listen_fd_, 8) != 0 ||
        getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
      std::abort();
    port_ = ntohs(a.sin_port);
    std::thread([this] { run(); }).detach();  // lives as long as the fuzzing process
  }
  int port() const { return port_; }
  void set_replies(std::vector<Reply> replies) {
    std::lock_guard lock(mu_);
    replies_ = std::move(replies);
    next_ = 0;
  }

 private:
  Reply take() {
    std::lock_guard lock(mu_);
    if (next_ < replies_.size()) return replies_[next_++];
    return Reply{0, {0x83, 0x04}};  // out of input: "server device failure"
  }
  static bool read_exactly(int fd, std::uint8_t* p, std::size_t n) {
    while (n > 0) {
      pollfd pfd{fd, POLLIN, 0};
      if (poll(&pfd, 1, 1000) != 1) return false;
      const ssize_t k = recv(fd, p, n, 0);
      if (k <= 0) return false;
      p += k;
      n -= static_cast<std::size_t>(k);
    }
    return true;
  }
  // Serves one request; false when the connection is over.
  bool serve(int fd) {
    std::uint8_t mbap[7];
    if (!read_exactly(fd, mbap, sizeof mbap)) return false;
    const std::size_t len = static_cast<std::size_t>(mbap[4] << 8 | mbap[5]);
    std::vector<std::uint8_t> pdu(len > 1 ? len - 1 : 0);
    if (len < 2 || len > 254 || !read_exactly(fd, pdu.data(), pdu.size())) return false;
    const Reply r = take();
    if (r.flags & kFlagHangUp) return false;
    std::vector<std::uint8_t> out(mbap, mbap + 7);
    if (r.flags & kFlagWrongTid) out[1] ^= 0x01;
    if (r.flags & kFlagWrongProtocol) out[3] = 1;
    if (r.flags & kFlagWrongUnit) out[6] ^= 0x01;
    out[4] = static_cast<std::uint8_t>((r.pdu.size() + 1) >> 8);
    out[5] = static_cast<std::uint8_t>(r.pdu.size() + 1);
    out.insert(out.end(), r.pdu.begin(), r.pdu.end());
    return send(fd, out.data(), out.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(out.size());
  }
  // Each client (one per driver) has its own connection; requests come one at a time.
  void run() {
    std::vector<int> clients;
    for (;;) {
      std::vector<pollfd> fds{{listen_fd_, POLLIN, 0}};
      for (int c : clients) fds.push_back({c, POLLIN, 0});
      if (poll(fds.data(), fds.size(), 1000) <= 0) continue;
      for (std::size_t i = 1; i < fds.size(); ++i) {
        if (fds[i].revents == 0 || serve(fds[i].fd)) continue;
        close(fds[i].fd);
        std::erase(clients, fds[i].fd);
      }
      if (fds[0].revents & POLLIN) {
        const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
        if (fd >= 0) clients.push_back(fd);
      }
    }
  }

  int listen_fd_ = -1;
  int port_ = 0;
  std::mutex mu_;
  std::vector<Reply> replies_;
  std::size_t next_ = 0;
};

std::vector<Reply> parse_replies(const std::uint8_t* data, std::size_t size) {
  std::vector<Reply> out;
  std::size_t i = 0;
  while (i + 2 <= size) {
    Reply r{data[i], {}};
    const std::size_t n = std::min<std::size_t>(data[i + 1], size - i - 2);
    r.pdu.assign(data + i + 2, data + i + 2 + n);
    out.push_back(std::move(r));
    i += 2 + n;
  }
  return out;
}

void check_chamber(const dr::Result<dr::ChamberState>& r) {
  if (!r) return;
  const auto& s = r.value();
  check(std::isfinite(s.air_c) || (std::isnan(s.air_c) && s.alarms.sensor_break), "air");
  check(
      std::isfinite(s.product_c) && std::isfinite(s.setpoint_c) && std::isfinite(s.ramp_c_per_min),
      "a non-finite chamber value was accepted");
  const int mode = static_cast<int>(s.mode);
  check(mode >= 0 && mode <= 3, "chamber mode outside its enum");
}

void check_table(const dr::Result<dr::TurntableState>& r) {
  if (!r) return;
  const auto& s = r.value();
  check(std::isfinite(s.angle_deg) && std::isfinite(s.rate_dps), "a non-finite table value");
  const int mode = static_cast<int>(s.mode);
  check(mode >= 0 && mode <= 2, "table mode outside its enum");
}

// Runs `call` and checks it came back within kCallBoundS.
template <typename F>
auto bounded(const char* what, F&& call) {
  const auto t0 = std::chrono::steady_clock::now();
  auto result = call();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  check(s < kCallBoundS, std::string(what) + " took " + std::to_string(s) + " s with a " +
                             std::to_string(kTimeoutS) + " s timeout per transaction");
  return result;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static FakeDevice device;
  const auto endpoint = mb::parse_endpoint("tcp://127.0.0.1:" + std::to_string(device.port()));
  static dr::ModbusChamber f4("f4", endpoint, dr::chamber_map::generic_plc(), kTimeoutS);
  static dr::ModbusChamber f4t("f4t", endpoint, dr::chamber_map::generic_plc_float(), kTimeoutS);
  static dr::ModbusTurntable table("table", endpoint, dr::turntable_map::generic_plc(), {},
                                   kTimeoutS);
  if (size < 1) return 0;
  device.set_replies(parse_replies(data + 1, size - 1));
  dr::ModbusChamber& chamber = data[0] & 0x01 ? f4t : f4;
  check_chamber(bounded("chamber read()", [&] { return chamber.read(); }));
  check_table(bounded("table read()", [&] { return table.read(); }));
  if (data[0] & 0x02) {
    dr::ChamberCommand c;
    c.setpoint_c = 30.0;
    c.ramp_c_per_min = 1.0;
    // The limits are read back first: they too come from the input.
    (void)bounded("chamber command()", [&] { return chamber.command(c); });
  }
  return 0;
}
