// Interoperability with Modbus peers we did not write: Debian's mbpoll reading (and writing)
// ChamberSim, and ModbusChamber reading a pymodbus 3.0 server that plays a Watlow F4.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <regex>
#include <string>
#include <thread>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "sim_devices/chamber_sim.hpp"
#include "sim_devices/servers/modbus_server.hpp"

namespace mb = station::drivers::modbus;
namespace cm = station::drivers::chamber_map;

namespace {

constexpr const char* kMbpoll = "/usr/bin/mbpoll";
constexpr const char* kPython = "/usr/bin/python3";

// Runs a shell command (already bounded by `timeout`), returns its stdout.
std::string run(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return out;
  char buf[512];
  while (fgets(buf, sizeof buf, p) != nullptr) out += buf;
  pclose(p);
  return out;
}

// mbpoll prints one "[REF]: \tVALUE" line per register.
std::map<int, int> parse_mbpoll(const std::string& out) {
  std::map<int, int> regs;
  std::regex line(R"(\[(\d+)\]:\s+(-?\d+))");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), line); it != std::sregex_iterator();
       ++it)
    regs[std::stoi((*it)[1])] = std::stoi((*it)[2]);
  return regs;
}

// Reads `count` holding registers from `ref` (PDU addressing), or writes `write_values`.
std::string mbpoll(int port, int ref, int count, const std::string& write_values = "") {
  std::string count_opt = write_values.empty() ? " -c " + std::to_string(count) : "";
  return run("timeout 10 " + std::string(kMbpoll) + " -m tcp -a 1 -t 4 -0 -1 -o 1 -p " +
             std::to_string(port) + " -r " + std::to_string(ref) + count_opt + " 127.0.0.1 " +
             write_values + " 2>&1");
}

// pymodbus cannot report an ephemeral port: take one from the kernel, release it, pass it on.
int free_port() {
  int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  close(s);
  return ntohs(a.sin_port);
}

// The pymodbus peer process; killed (by its pid) and reaped on destruction.
struct PythonPeer {
  explicit PythonPeer(int port) {
    std::string script = STATION_SOURCE_DIR "/tests/drivers/peers/chamber_peer.py";
    std::string port_s = std::to_string(port);
    pid = fork();
    if (pid == 0) {
      execl(kPython, kPython, script.c_str(), port_s.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
  }
  ~PythonPeer() {
    if (pid <= 0) return;
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
  }
  pid_t pid = -1;
};

bool has_pymodbus() {
  return access(kPython, X_OK) == 0 &&
         run("timeout 20 " + std::string(kPython) + " -c 'import pymodbus.server' 2>&1; echo rc=$?")
                 .find("rc=0") != std::string::npos;
}

}  // namespace

TEST(ModbusPeers, MbpollReadsAndWritesTheSimulatedChamber) {
  if (access(kMbpoll, X_OK) != 0) GTEST_SKIP() << kMbpoll << " not installed";
  auto map = cm::generic_plc();
  station::sim::ChamberSimConfig cfg;
  cfg.initial_c = 31.7;
  station::sim::ChamberSim sim(map, cfg);
  station::sim::ModbusServer server(sim);
  server.start_tcp();
  auto regs = parse_mbpoll(mbpoll(server.port(), 100, 1));
  ASSERT_EQ(regs.count(100), 1u) << mbpoll(server.port(), 100, 1);
  EXPECT_EQ(regs[100], 317);                                         // air 31.7 C in tenths
  EXPECT_EQ(parse_mbpoll(mbpoll(server.port(), 104, 1))[104], 317);  // product
  // 101..103 are not implemented: a block over them is refused, as a real F4 refuses it.
  EXPECT_NE(mbpoll(server.port(), 100, 5).find("Illegal data address"), std::string::npos);
  auto limits = parse_mbpoll(mbpoll(server.port(), 602, 2));
  EXPECT_EQ(limits[602], 65536 - 700);  // -70.0 C; mbpoll -t 4 shows the word unsigned
  EXPECT_EQ(limits[603], 1800);
  // mbpoll writes setpoint 20.0 C (it rejects negative 16-bit values); the model takes it.
  EXPECT_NE(mbpoll(server.port(), 300, 1, "200").find("Written 1 references"), std::string::npos);
  auto sp = parse_mbpoll(mbpoll(server.port(), 300, 1));
  EXPECT_EQ(sp[300], 200);
  sim.step_to(60.0);
  EXPECT_LT(sim.air_c(), 31.7);  // cooling toward 20 C
}

TEST(ModbusPeers, ChamberDriverReadsAPymodbusServer) {
  if (!has_pymodbus()) GTEST_SKIP() << kPython << " with pymodbus not available";
  int port = free_port();
  PythonPeer peer(port);
  station::drivers::ModbusChamber chamber("chamber-pymodbus", mb::TcpEndpoint{"127.0.0.1", port},
                                          cm::generic_plc(), 0.5);
  // Bounded wait for the interpreter to come up: 100 tries x 100 ms.
  bool up = false;
  for (int i = 0; i < 100 && !up; ++i) {
    up = chamber.connect().ok();
    if (!up) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(up) << "pymodbus peer did not listen on port " << port;
  auto s = chamber.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_DOUBLE_EQ(s.value().air_c, 23.4);
  EXPECT_DOUBLE_EQ(s.value().product_c, 21.0);
  EXPECT_DOUBLE_EQ(s.value().setpoint_c, 23.5);
  EXPECT_DOUBLE_EQ(s.value().ramp_c_per_min, 1.5);
  EXPECT_EQ(s.value().mode, station::drivers::ChamberMode::constant);
  EXPECT_TRUE(s.value().run_enabled);
  EXPECT_EQ(chamber.command({.setpoint_c = 90.0}).error().kind,
            station::drivers::ErrorKind::range);  // above the peer's 85.0 C limit
  ASSERT_TRUE(chamber.command({.setpoint_c = -40.0, .ramp_c_per_min = 1.0}));
  auto back = chamber.read();
  ASSERT_TRUE(back);
  EXPECT_DOUBLE_EQ(back.value().setpoint_c, -40.0);
  EXPECT_DOUBLE_EQ(back.value().ramp_c_per_min, 1.0);
}
