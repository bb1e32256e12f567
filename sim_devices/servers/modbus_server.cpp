// ModbusServer: a poll()-driven libmodbus server thread, TCP or RTU-on-pty, with fault injection.
#include "sim_devices/servers/modbus_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "sim_devices/servers/rtu_framing.hpp"

namespace station::sim {
namespace {

constexpr int kPollMs = 100;
// End of an RTU frame: 3.5 characters are 2 ms at 19200 baud; a pty delivers a frame written at
// once within microseconds, so a few ms of silence delimit frames without splitting one.
constexpr int kRtuSilenceMs = 5;

// Whole Modbus TCP frames at the front of `buf` (by their MBAP headers; a bad one ends the count).
std::size_t whole_tcp_frames(const std::vector<std::uint8_t>& buf) {
  std::size_t n = 0;
  for (std::size_t at = 0; at + 6 <= buf.size(); ++n) {
    const std::size_t length = (std::size_t{buf[at + 4]} << 8) | buf[at + 5];
    if (buf[at + 2] != 0 || buf[at + 3] != 0 || length < 2 || at + 6 + length > buf.size()) break;
    at += 6 + length;
  }
  return n;
}

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

[[noreturn]] void sys_fail(const std::string& what) {
  throw std::runtime_error("modbus server: " + what + ": " + std::strerror(errno));
}

std::uint16_t* table(const modbus_mapping_t& regs, const drivers::modbus::Point& p) {
  return p.function == drivers::modbus::FunctionCode::input ? regs.tab_input_registers
                                                            : regs.tab_registers;
}

}  // namespace

int register_count(const drivers::modbus::RegisterMap& map) {
  int n = 0;
  for (const auto& [name, p] : map.points()) n = std::max(n, p.pdu_address() + p.word_count());
  return n;
}

void put_point(modbus_mapping_t& regs, const drivers::modbus::Point& p, double value) {
  auto words = drivers::modbus::encode_point(p, value);
  if (!words && p.type == drivers::modbus::PointType::float32 && !std::isfinite(value)) {
    // A float register carries NaN as IEEE-754 does: the words a controller sends for a process
    // value whose input failed (docs/DEVICES.md), not a value to drop or saturate.
    words = drivers::modbus::float_to_words(static_cast<float>(value), p.order);
  }
  if (!words) {
    // Saturate like a controller display would rather than publish garbage.
    double lim = p.type == drivers::modbus::PointType::uint16 ? 65535.0 : 32767.0;
    double lo = p.type == drivers::modbus::PointType::uint16 ? 0.0 : -32768.0;
    words = drivers::modbus::encode_point(p, std::clamp(value / p.scale, lo, lim) * p.scale);
    if (!words) return;
  }
  std::uint16_t* t = table(regs, p) + p.pdu_address();
  for (int i = 0; i < p.word_count(); ++i) t[i] = (*words)[i];
}

double get_point(const modbus_mapping_t& regs, const drivers::modbus::Point& p) {
  return drivers::modbus::decode_point(p, table(regs, p) + p.pdu_address());
}

bool point_written(const drivers::modbus::Point& p, std::uint16_t pdu_address, int count) {
  int a = p.pdu_address();
  return p.function == drivers::modbus::FunctionCode::holding && a < pdu_address + count &&
         pdu_address < a + p.word_count();
}

void ModbusServer::FreeServerCtx::operator()(modbus_t* c) const noexcept {
  modbus_set_socket(c, -1);  // descriptors are owned by the server, not by the context
  modbus_free(c);
}

ModbusServer::ModbusServer(ModbusDeviceModel& model, int unit_id)
    : model_(model), unit_id_(unit_id) {}

ModbusServer::~ModbusServer() {
  stop();
}

void ModbusServer::make_mapping() {
  int n = model_.register_count();
  mapping_.reset(modbus_mapping_new(0, 0, n, n));
  if (!mapping_) sys_fail("modbus_mapping_new");
}

void ModbusServer::start_tcp(int port, UnitLink link) {
  if (port < 0 || port > 65535)
    throw std::runtime_error("modbus server: port " + std::to_string(port) + " not 0..65535");
  if (link == UnitLink::rtu) throw std::runtime_error("modbus server: TCP needs a TCP link");
  link_ = link;
  make_mapping();
  ctx_.reset(modbus_new_tcp("127.0.0.1", port));
  if (!ctx_) sys_fail("modbus_new_tcp");
  listen_fd_ = modbus_tcp_listen(ctx_.get(), 8);
  if (listen_fd_ == -1) sys_fail("modbus_tcp_listen 127.0.0.1:" + std::to_string(port));
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  if (getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len) == -1)
    sys_fail("getsockname");
  port_ = ntohs(addr.sin_port);
  tcp_ = listening_ = true;
  open_capture();
  thread_ = std::thread([this] { run_tcp(); });
}

void ModbusServer::start_rtu_pty(int baud) {
  link_ = UnitLink::rtu;
  make_mapping();
  baud_ = baud;
  pty_master_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (pty_master_ == -1) sys_fail("posix_openpt");
  if (grantpt(pty_master_) == -1 || unlockpt(pty_master_) == -1) sys_fail("grantpt/unlockpt");
  char name[128];
  if (ptsname_r(pty_master_, name, sizeof name) != 0) sys_fail("ptsname_r");
  pty_path_ = name;
  pty_slave_ = open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (pty_slave_ == -1) sys_fail("open " + pty_path_);
  termios tios{};
  tcgetattr(pty_slave_, &tios);
  cfmakeraw(&tios);  // no echo, no line editing: bytes pass as they are
  tcsetattr(pty_slave_, TCSANOW, &tios);
  ctx_.reset(modbus_new_rtu(name, baud, 'N', 8, 1));
  if (!ctx_) sys_fail("modbus_new_rtu");
  modbus_set_slave(ctx_.get(), unit_id_);
  open_capture();
  thread_ = std::thread([this] { run_rtu(); });
}

void ModbusServer::stop() {
  stop_ = true;
  tcp_ = false;  // nothing to settle any more
  if (thread_.joinable()) thread_.join();
  for (int* fd : {&listen_fd_, &pty_master_, &pty_slave_, &capture_[0], &capture_[1]}) {
    if (*fd != -1) close(*fd);
    *fd = -1;
  }
}

std::string ModbusServer::endpoint() const {
  if (!pty_path_.empty())
    return "rtu:" + pty_path_ + "?baud=" + std::to_string(baud_) + "&parity=N&data=8&stop=1";
  return "tcp://127.0.0.1:" + std::to_string(port_);
}

void ModbusServer::open_capture() {
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, capture_) == -1) sys_fail("socketpair");
}

bool ModbusServer::send_reply(const std::function<int()>& build) {
  const int fd = modbus_get_socket(ctx_.get());
  const double interval_s = faults_.drip_interval_s();
  const bool drip = interval_s > 0 || drips_.busy(fd);
  if (drip && gathering_ && !send_gathered(fd)) return false;  // what was before it, first
  if (!drip && !gathering_) return build() != -1;
  modbus_set_socket(ctx_.get(), capture_[0]);
  const int rc = build();
  modbus_set_socket(ctx_.get(), fd);
  if (gathering_) return rc != -1;
  std::uint8_t bytes[MODBUS_TCP_MAX_ADU_LENGTH];
  const ssize_t n = recv(capture_[1], bytes, sizeof bytes, MSG_DONTWAIT);
  if (n > 0) drips_.push(fd, {bytes, static_cast<std::size_t>(n)}, interval_s);
  return rc != -1;
}

bool ModbusServer::send_gathered(int fd) {
  gathering_ = false;
  std::vector<std::uint8_t> out;
  std::uint8_t chunk[4096];
  for (ssize_t n = sizeof chunk; n == static_cast<ssize_t>(sizeof chunk);) {  // all of it
    n = recv(capture_[1], chunk, sizeof chunk, MSG_DONTWAIT);
    if (n > 0) out.insert(out.end(), chunk, chunk + n);
  }
  for (std::size_t done = 0; done < out.size();) {
    const ssize_t n = send(fd, out.data() + done, out.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

void ModbusServer::accept_client(std::vector<int>& clients) {
  int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
  if (fd != -1) clients.push_back(fd);
}

// Applies an injected disconnect: drops the clients and the listener, and listens again on the
// same port once the down time is over. False while the link is down.
bool ModbusServer::tcp_link_up(std::vector<int>& clients) {
  double down_until = 0;
  const std::uint64_t asked = faults_.kicks(down_until);
  if (asked != kicks_applied_.load()) {
    for (int c : clients) close(c), drips_.forget(c);
    clients.clear();
    pending_.clear();
    if (listen_fd_ != -1) close(listen_fd_);
    listen_fd_ = -1;
    listening_ = false;
    kicks_applied_ = asked;
  }
  if (listen_fd_ != -1) return true;
  if (faults_.now_s() < down_until) return false;
  ctx_.reset(modbus_new_tcp("127.0.0.1", port_));
  if (ctx_) listen_fd_ = modbus_tcp_listen(ctx_.get(), 8);
  listening_ = listen_fd_ != -1;
  return listen_fd_ != -1;
}

void ModbusServer::run_tcp() {
  std::vector<int> clients;
  while (!stop_) {
    if (!tcp_link_up(clients)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      continue;
    }
    std::vector<pollfd> fds{{listen_fd_, POLLIN, 0}};
    for (int c : clients) fds.push_back({c, POLLIN, 0});
    const int ready = poll(fds.data(), fds.size(), drips_.poll_ms(kPollMs));
    drips_.send_due();
    if (ready <= 0) continue;
    if (fds[0].revents & POLLIN) accept_client(clients);
    for (std::size_t i = 1; i < fds.size(); ++i) {
      if (fds[i].revents == 0 || serve_one(fds[i].fd)) continue;
      drips_.forget(fds[i].fd);
      close(fds[i].fd);
      clients.erase(std::find(clients.begin(), clients.end(), fds[i].fd));
    }
  }
  for (int c : clients) close(c), drips_.forget(c);
  pending_.clear();
}

// RTU frames are read here, not by modbus_receive(): libmodbus 3.1.6 stops reading a frame for
// another unit after its header and takes the rest of it for the next frame, after which it
// ignores its own unit's requests too (seen on a multidrop line with two units).
void ModbusServer::run_rtu() {
  std::uint8_t frame[MODBUS_RTU_MAX_ADU_LENGTH];
  modbus_set_socket(ctx_.get(), pty_master_);
  while (!stop_) {
    pollfd pfd{pty_master_, POLLIN, 0};
    const int ready = poll(&pfd, 1, drips_.poll_ms(kPollMs));
    drips_.send_due();
    if (ready <= 0 || !(pfd.revents & POLLIN)) continue;
    const double arrived_s = steady_now_s();
    const int len = read_rtu_frame(pty_master_, frame, sizeof frame, kRtuSilenceMs);
    if (rtu_frame_ok({frame, static_cast<std::size_t>(len)})) dispatch(frame, len, arrived_s);
  }
}

// One recv per request instead of libmodbus's select/recv/select/recv: the Modbus TCP frame is
// cut from the client's byte stream by its MBAP header (Modbus Messaging on TCP/IP
// Implementation Guide v1.0b, 3.1.3: transaction id, protocol id 0, length of the unit id and
// PDU). A frame split across segments waits for the rest; a bad header closes the connection,
// as libmodbus does. Several requests in one read (a client with several outstanding, §3.1.3)
// are answered in order and their replies sent in one send, each reply's bytes as alone (one
// wake-up of the client, not one a reply); what came before a drop or a bad header still goes.
bool ModbusServer::serve_one(int fd) {
  auto& buf = pending_[fd];
  std::uint8_t chunk[MODBUS_TCP_MAX_ADU_LENGTH];
  const ssize_t n = recv(fd, chunk, sizeof chunk, MSG_DONTWAIT);
  if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) return forget(fd);
  if (n > 0) buf.insert(buf.end(), chunk, chunk + n);
  gathering_ = whole_tcp_frames(buf) > 1;
  const auto close_it = [&] {
    if (gathering_) (void)send_gathered(fd);
    return forget(fd);
  };
  constexpr std::size_t kMbap = 7;  // transaction 2, protocol 2, length 2, unit 1
  while (buf.size() >= kMbap) {
    const std::size_t length = (std::size_t{buf[4]} << 8) | buf[5];  // unit id + PDU
    if (buf[2] != 0 || buf[3] != 0 || length < 2 || 6 + length > MODBUS_TCP_MAX_ADU_LENGTH)
      return close_it();
    if (buf.size() < 6 + length) break;
    std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
    std::copy_n(buf.begin(), 6 + length, query);
    buf.erase(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(6 + length));
    modbus_set_socket(ctx_.get(), fd);
    if (!dispatch(query, static_cast<int>(6 + length), steady_now_s())) return close_it();
  }
  return !gathering_ || send_gathered(fd) || forget(fd);
}

bool ModbusServer::forget(int fd) {
  pending_.erase(fd);
  return false;
}

std::vector<double> ModbusServer::request_arrivals_s() const {
  const std::lock_guard<std::mutex> lock(arrivals_mutex_);
  return arrivals_s_;
}

// The unit id decides first (unit_address.hpp): another unit's frame is not a request to this one.
bool ModbusServer::dispatch(const std::uint8_t* query, int len, double arrived_s) {
  const int header = modbus_get_header_length(ctx_.get());  // the unit id is its last byte
  if (len < header + 1) return true;
  const UnitAnswer a = unit_answer(link_, unit_id_, query[header - 1], query[header]);
  if (a == UnitAnswer::silence) return true;
  if (a == UnitAnswer::gateway_error)
    return send_reply(
        [&] { return modbus_reply_exception(ctx_.get(), query, kGatewayTargetFailed); });
  {
    const std::lock_guard<std::mutex> lock(arrivals_mutex_);
    arrivals_s_.push_back(arrived_s);
  }
  return handle(query, len, a == UnitAnswer::serve);
}

// `reply` false: a broadcast, executed and never answered.
bool ModbusServer::handle(const std::uint8_t* query, int len, bool reply) {
  ++requests_;
  int code = 0;
  switch (faults_.take(code)) {
    case FaultSchedule::Fault::timeout:
      return true;
    case FaultSchedule::Fault::drop:
      return pty_master_ != -1;  // TCP: close; RTU: just stay silent
    case FaultSchedule::Fault::exception:
      return !reply || send_reply([&] {
        return modbus_reply_exception(ctx_.get(), query, static_cast<unsigned>(code));
      });
    case FaultSchedule::Fault::none:
      break;
  }
  const int header = modbus_get_header_length(ctx_.get());
  const int crc = pty_master_ != -1 ? 2 : 0;  // RTU frames end with a CRC
  if (len < header + crc + 1) return true;
  const std::span<const std::uint8_t> pdu(query + header,
                                          static_cast<std::size_t>(len - header - crc));
  if (const std::uint8_t e = strict_exception(pdu); e != 0)
    return !reply || send_reply([&] { return modbus_reply_exception(ctx_.get(), query, e); });
  model_.publish(*mapping_);
  // Apply a write to the model BEFORE the reply leaves, so a client that has its reply sees the
  // model already changed (no race with the next step_to()).
  apply_writes(pdu);
  return !reply || send_reply([&] { return modbus_reply(ctx_.get(), query, len, mapping_.get()); });
}

std::uint8_t ModbusServer::strict_exception(std::span<const std::uint8_t> pdu) const {
  if (const std::uint8_t e = request_exception(model_.register_map(), pdu); e != 0) return e;
  const auto w = parse_write(pdu);
  return w ? model_.check_write(*w) : 0;
}

void ModbusServer::apply_writes(std::span<const std::uint8_t> pdu) {
  const auto w = parse_write(pdu);
  if (!w || w->address + w->count() > mapping_->nb_registers) return;
  for (int i = 0; i < w->count(); ++i) mapping_->tab_registers[w->address + i] = w->word(i);
  model_.on_write(*mapping_, w->address, w->count());
}

}  // namespace station::sim
