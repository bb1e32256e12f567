// A reusable in-process Modbus server (libmodbus) over TCP on 127.0.0.1 or RTU on a pty, whose
// registers are backed by a device model, with fault injection for driver tests.
#pragma once

#include <modbus/modbus.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "drivers/modbus/register_map.hpp"
#include "sim_devices/servers/drip_queue.hpp"
#include "sim_devices/servers/fault_schedule.hpp"
#include "sim_devices/servers/modbus_strict.hpp"
#include "sim_devices/servers/sim_server.hpp"
#include "sim_devices/servers/unit_address.hpp"

namespace station::sim {

/// Registers a map needs in each table: highest PDU address + words.
int register_count(const drivers::modbus::RegisterMap& map);
/// Encodes `value` into the point's table (holding or input); values that do not fit saturate.
void put_point(modbus_mapping_t& regs, const drivers::modbus::Point& p, double value);
/// Decodes the point's current holding/input words.
double get_point(const modbus_mapping_t& regs, const drivers::modbus::Point& p);
/// True if the point's words intersect [pdu_address, pdu_address + count).
bool point_written(const drivers::modbus::Point& p, std::uint16_t pdu_address, int count);

/// A device whose state the server exposes as registers. Called from the server thread only.
class ModbusDeviceModel {
 public:
  virtual ~ModbusDeviceModel() = default;
  /// The map the device serves: a request outside it gets an exception (request_exception).
  virtual const drivers::modbus::RegisterMap& register_map() const = 0;
  /// Exception code (kIllegalDataValue) for a write of a value the device refuses, else 0.
  virtual std::uint8_t check_write(const RegisterWrite& /*write*/) const { return 0; }
  /// Registers needed (holding and input tables each): highest PDU address + 1.
  virtual int register_count() const = 0;
  /// Copies the model's current state into the register tables (before every reply).
  virtual void publish(modbus_mapping_t& regs) = 0;
  /// Applies holding registers [pdu_address, pdu_address + count) just written by a client.
  virtual void on_write(const modbus_mapping_t& regs, std::uint16_t pdu_address, int count) = 0;
};

/// Serves one model as a strict device: requests outside its map get exception 01/02/03, and a
/// request for another unit id is answered as the unit's link does (unit_address.hpp: silence on
/// a serial line or the unit's own TCP port, exception 0x0B from a gateway). start_*() spawns the
/// thread; the destructor stops and joins it (the loop polls with a 100 ms timeout, so shutdown
/// never hangs).
class ModbusServer final : public SimServer {
 public:
  /// Stores the model (not owned; must outlive the server) and unit id; no I/O.
  explicit ModbusServer(ModbusDeviceModel& model, int unit_id = 1);
  ~ModbusServer() override;
  ModbusServer(const ModbusServer&) = delete;
  ModbusServer& operator=(const ModbusServer&) = delete;

  /// Listens on 127.0.0.1:port (0 = ephemeral) and starts serving as `link` (the unit's own TCP
  /// port, or a TCP-to-RTU gateway in front of it); throws std::runtime_error.
  void start_tcp(int port = 0, UnitLink link = UnitLink::tcp_device);
  /// Opens a pty pair and serves RTU on its master; clients open pty_path(). Throws on failure.
  void start_rtu_pty(int baud = 19200);
  /// Stops the thread and closes every descriptor; blocks at most ~100 ms. Idempotent.
  void stop() override;

  /// TCP port chosen by the kernel (0 before start_tcp).
  int port() const { return port_; }
  /// Pty slave path (empty before start_rtu_pty).
  const std::string& pty_path() const { return pty_path_; }
  /// Endpoint string for drivers: tcp://127.0.0.1:PORT or rtu:/dev/pts/N?baud=..&parity=N&...
  std::string endpoint() const override;
  /// Requests received so far (including faulted ones).
  std::uint64_t requests() const override { return requests_.load(); }
  /// When each of those requests began to arrive, steady-clock seconds (RTU: the first byte of
  /// the frame; TCP: the whole frame). Thread-safe.
  std::vector<double> request_arrivals_s() const;
  /// How the unit is reached (set by start_*()).
  UnitLink link() const { return link_; }

 private:
  struct FreeServerCtx {
    void operator()(modbus_t* c) const noexcept;
  };
  struct FreeMapping {
    void operator()(modbus_mapping_t* m) const noexcept { modbus_mapping_free(m); }
  };

  void make_mapping();
  void run_tcp();
  void run_rtu();
  bool tcp_link_up(std::vector<int>& clients);
  void accept_client(std::vector<int>& clients);
  bool serve_one(int fd);
  bool forget(int fd);  ///< drops a client's partial frame; false (close it)
  bool dispatch(const std::uint8_t* query, int len, double arrived_s);
  bool handle(const std::uint8_t* query, int len, bool reply);
  /// Sends the reply `build` makes (a libmodbus modbus_reply*): at once, or a byte at a time
  /// while a drip is on (or queued behind one), captured from a socketpair first; while a batch
  /// is gathered, captured for send_gathered.
  bool send_reply(const std::function<int()>& build);
  /// Sends `fd` the replies gathered in the capture socketpair, in one send; false when the
  /// client is gone. Ends the gathering.
  bool send_gathered(int fd);
  void open_capture();
  std::uint8_t strict_exception(std::span<const std::uint8_t> pdu) const;
  void apply_writes(std::span<const std::uint8_t> pdu);

  ModbusDeviceModel& model_;
  int unit_id_;
  UnitLink link_ = UnitLink::tcp_device;
  std::unique_ptr<modbus_t, FreeServerCtx> ctx_;
  std::unique_ptr<modbus_mapping_t, FreeMapping> mapping_;
  int listen_fd_ = -1;
  int pty_master_ = -1;
  int pty_slave_ = -1;  // held open so the master never sees a hang-up between clients
  int port_ = 0;
  int baud_ = 19200;
  std::string pty_path_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> requests_{0};
  mutable std::mutex arrivals_mutex_;
  std::vector<double> arrivals_s_;  // guarded by arrivals_mutex_
  std::thread thread_;
  std::map<int, std::vector<std::uint8_t>> pending_;  // per TCP client: bytes of a partial frame
  int capture_[2] = {-1, -1};  // socketpair a dripped or gathered reply is built into
  bool gathering_ = false;     // the replies to the requests of one read go out in one send
  DripQueue drips_;
};

}  // namespace station::sim
