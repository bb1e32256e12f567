// simrig's control socket: the line protocol of ControlSocket over a real unix stream socket, the
// paths it refuses, and the simrig program taking fault commands from `simrig --send`.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "sim_devices/control_socket.hpp"

namespace sim = station::sim;

namespace {

const std::string kSimrig = std::string(STATION_BINARY_DIR) + "/sim_devices/simrig";

std::string temp_path(const std::string& name) {
  return testing::TempDir() + name + "-" + std::to_string(getpid());
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Serves `socket` on this thread until `client` has finished (bounded: 10 s).
void serve_until_done(sim::ControlSocket& socket, std::thread& client, std::atomic<bool>& done) {
  for (int i = 0; i < 1000 && !done; ++i) socket.service(10);
  client.join();
}

std::string echo(std::string_view line) {
  return line == "bad" ? "error: bad" : "ok " + std::string(line);
}

int connect_raw(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
  const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  return fd;
}

// Runs simrig with `args`; returns its exit status and stdout.
std::pair<int, std::string> run_simrig(const std::string& args) {
  std::string out;
  FILE* p = popen(("timeout 10 " + kSimrig + " " + args + " 2>&1").c_str(), "r");
  char buf[512];
  while (p != nullptr && fgets(buf, sizeof buf, p) != nullptr) out += buf;
  const int status = p != nullptr ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace

TEST(ControlSocket, OneReplyLinePerCommandLine) {
  const std::string path = temp_path("ctl-lines");
  sim::ControlSocket socket(path, echo);
  std::atomic<bool> done{false};
  std::vector<std::string> replies;
  std::string raw_replies;
  std::thread client([&] {
    replies = sim::send_control_commands(path, {"door open", "bad", "status"});
    // Two lines in one write, one of them ending in CR LF (telnet, socat -t), one split in two.
    const int fd = connect_raw(path);
    const std::string burst = "a b\r\nc\nd";
    send(fd, burst.data(), burst.size(), 0);
    send(fd, "e\n", 2, 0);
    char buf[256];
    while (std::count(raw_replies.begin(), raw_replies.end(), '\n') < 3) {
      const ssize_t n = recv(fd, buf, sizeof buf, 0);
      if (n <= 0) break;
      raw_replies.append(buf, static_cast<std::size_t>(n));
    }
    close(fd);
    done = true;
  });
  serve_until_done(socket, client, done);
  EXPECT_EQ(replies, (std::vector<std::string>{"ok door open", "error: bad", "ok status"}));
  EXPECT_EQ(raw_replies, "ok a b\nok c\nok de\n");
}

TEST(ControlSocket, AnOverlongLineIsAnErrorAndTheClientIsDropped) {
  const std::string path = temp_path("ctl-long");
  sim::ControlSocket socket(path, echo);
  std::atomic<bool> done{false};
  std::string reply;
  std::thread client([&] {
    const int fd = connect_raw(path);
    const std::string junk(sim::kMaxControlLine + 600, 'x');
    send(fd, junk.data(), junk.size(), MSG_NOSIGNAL);
    char buf[256];
    for (ssize_t n; (n = recv(fd, buf, sizeof buf, 0)) > 0;) reply.append(buf, n);
    close(fd);  // recv returned 0: the server closed the connection
    done = true;
  });
  serve_until_done(socket, client, done);
  EXPECT_EQ(reply, "error: line longer than 1024 bytes\n");
}

TEST(ControlSocket, RefusesAFileAndALiveSocketAndReplacesAStaleOne) {
  const std::string file = temp_path("ctl-file");
  std::ofstream(file) << "precious\n";
  EXPECT_THROW(sim::ControlSocket(file, echo), std::runtime_error);
  EXPECT_EQ(slurp(file), "precious\n");
  unlink(file.c_str());

  const std::string path = temp_path("ctl-stale");
  {
    // A socket file whose listener is gone (a simrig killed with SIGKILL leaves one).
    const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
    ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    close(fd);
  }
  sim::ControlSocket live(path, echo);
  EXPECT_THROW(sim::ControlSocket(path, echo), std::runtime_error);  // live is listening
  EXPECT_THROW(sim::send_control_commands(temp_path("ctl-nothing"), {"status"}),
               std::runtime_error);
}

// The program: --control serves fault commands, --send delivers them; the station's chamber
// driver sees the result over Modbus TCP.
TEST(SimrigControl, SendDeliversFaultCommandsToARunningSimrig) {
  ASSERT_EQ(access(kSimrig.c_str(), X_OK), 0) << kSimrig;
  const std::string ctl = temp_path("simrig-ctl"), can = temp_path("simrig-can");
  const std::string out = temp_path("simrig-ctl.out");
  const pid_t pid = fork();
  if (pid == 0) {
    const int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int devnull = open("/dev/null", O_WRONLY);
    if (o < 0 || dup2(o, 1) < 0 || dup2(devnull, 2) < 0) _exit(126);
    execl(kSimrig.c_str(), "simrig", "--gyros", "1", "--can-socket", can.c_str(), "--control",
          ctl.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  ASSERT_GT(pid, 0);
  std::smatch m;
  std::string text;
  const std::regex endpoint(R"(# chamber +\S+ (tcp://\S+))");
  for (int i = 0; i < 250 && !std::regex_search(text, m, endpoint); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    text = slurp(out);
  }
  ASSERT_TRUE(std::regex_search(text, m, endpoint)) << text;
  const std::string chamber_endpoint = m[1];
  EXPECT_NE(text.find("--control " + ctl), std::string::npos) << text;

  const auto [rc, replies] =
      run_simrig("--control " + ctl + " --send 'chamber alarm high-limit on' 'door open'");
  EXPECT_EQ(rc, 0) << replies;
  EXPECT_EQ(replies, "ok\nok\n");
  namespace mb = station::drivers::modbus;
  station::drivers::ModbusChamber chamber("chamber", mb::parse_endpoint(chamber_endpoint),
                                          station::drivers::chamber_map::generic_plc(), 0.5);
  auto s = chamber.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_TRUE(s.value().alarms.high_limit_trip);
  EXPECT_TRUE(s.value().alarms.door_open);

  const auto [bad_rc, bad] = run_simrig("--control " + ctl + " --send 'door ajar'");
  EXPECT_EQ(bad_rc, 1);
  EXPECT_EQ(bad, "error: usage: door open|close\n");
  EXPECT_EQ(run_simrig("--send status").first, 2);  // no --control: nothing to send to

  kill(pid, SIGTERM);
  int status = 0;
  bool exited = false;
  for (int i = 0; i < 250 && !exited; ++i) {
    exited = waitpid(pid, &status, WNOHANG) == pid;
    if (!exited) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!exited) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_NE(access(ctl.c_str(), F_OK), 0) << "control socket left behind";
}
