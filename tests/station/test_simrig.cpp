// The standalone `simrig` program: prints a usable station config for its endpoints, serves a
// probe over real sockets on the wall clock, and exits 0 on SIGTERM.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "station/config/config.hpp"
#include "station/daemon/rig_probe.hpp"

namespace {

const std::string kSimrig = std::string(STATION_BINARY_DIR) + "/sim_devices/simrig";

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Starts simrig with stdout/stderr to files; returns its pid (-1 on failure).
pid_t spawn_simrig(const std::string& sock, const std::string& out, const std::string& err) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  const int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (o < 0 || e < 0 || dup2(o, 1) < 0 || dup2(e, 2) < 0) _exit(126);
  execl(kSimrig.c_str(), "simrig", "--gyros", "2", "--seed", "5", "--can-socket", sock.c_str(),
        static_cast<char*>(nullptr));
  _exit(127);
}

// Waits up to `limit` for the child to exit; its wait status, or -1 (then it is killed).
int wait_bounded(pid_t pid, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return -1;
}

}  // namespace

TEST(Simrig, PrintsAUsableConfigServesAProbeAndStopsOnSigterm) {
  if (access(kSimrig.c_str(), X_OK) != 0) {
    FAIL() << kSimrig << " not built: the simrig target needs station_sim_devices to link "
           << "station::drivers (the frame codecs) in sim_devices/CMakeLists.txt";
  }
  const std::string dir = testing::TempDir();
  const std::string sock = dir + "simrig-test-" + std::to_string(getpid()) + ".sock";
  const std::string out = dir + "simrig-test.out", err = dir + "simrig-test.err";
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = spawn_simrig(sock, out, err);
  ASSERT_GT(pid, 0);
  // The config is flushed before serving starts; wait for it (bounded).
  std::string text;
  for (int i = 0; i < 250 && text.find("SIM-0002") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    text = slurp(out);
  }
  EXPECT_NE(text.find("tcp://127.0.0.1:"), std::string::npos) << text << slurp(err);
  station::StationConfig config;
  try {
    config = station::parse_station_config(text, out);
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what() << "\n" << text;
  }
  EXPECT_EQ(config.can_transport, "unix:" + sock);
  EXPECT_EQ(config.slots.size(), 2u);
  // Twice: simrig takes a new station after the first one leaves (it notices within ~150 ms).
  for (int round = 0; round < 2 && config.slots.size() == 2; ++round) {
    std::ostringstream probe_out;
    EXPECT_EQ(station::probe_rig(config, {}, probe_out, false), 0) << round << probe_out.str();
    EXPECT_NE(probe_out.str().find("SIM-0002"), std::string::npos) << probe_out.str();
    EXPECT_NE(probe_out.str().find("air 25.0 C"), std::string::npos) << probe_out.str();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  std::this_thread::sleep_until(start + std::chrono::seconds(1));
  kill(pid, SIGTERM);
  const int status = wait_bounded(pid, std::chrono::seconds(5));
  ASSERT_NE(status, -1) << "simrig did not stop within 5 s of SIGTERM";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status << "\n" << slurp(err);
  EXPECT_NE(slurp(err).find("station disconnected"), std::string::npos) << slurp(err);
  EXPECT_NE(access(sock.c_str(), F_OK), 0) << "socket file left behind";
}
