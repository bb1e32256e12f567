// Test helper: a simrig process on the wall clock and `station` processes against it, as a
// person would run them (real sockets, real SQLite file, real signals).
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace station::testing_support {

inline const std::string kSimrigBin = std::string(STATION_BINARY_DIR) + "/sim_devices/simrig";
inline const std::string kStationBin = std::string(STATION_BINARY_DIR) + "/station/station";

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A `station` command's exit status (-1 when it did not exit normally) and its stdout+stderr.
struct StationOutcome {
  int status = -1;
  std::string out;
};

/// Runs `station ARGS` through the shell (ARGS quoted as a shell would need), `tag` naming its
/// output file; waits for it.
inline StationOutcome station_command(const std::string& args, const std::string& tag) {
  const std::string out = ::testing::TempDir() + tag + "-" + std::to_string(getpid()) + ".out";
  const int rc = std::system((kStationBin + " " + args + " >" + out + " 2>&1").c_str());
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(out)};
}

/// Forks and execs `args[0]` with stdout to `out` and stderr to `err`; the child's pid.
inline pid_t spawn_process(const std::vector<std::string>& args, const std::string& out,
                           const std::string& err) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  const int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (o < 0 || e < 0 || dup2(o, 1) < 0 || dup2(e, 2) < 0) _exit(126);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execv(argv[0], argv.data());
  _exit(127);
}

/// Waits up to `limit` for the child to exit: its wait status, or -1 (then it is killed).
inline int wait_bounded(pid_t pid, std::chrono::milliseconds limit) {
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

/// Polls `done` every 50 ms for up to `limit`; true when it held.
template <class F>
bool wait_until(F done, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

/// A simrig process and the station config it printed, written to `config_path`.
struct SimrigProcess {
  pid_t pid = -1;
  std::string config_path, out, err, can_socket;
  std::vector<std::string> extra_args;

  /// Starts simrig with `gyros` gyros; true once its config is complete on stdout.
  bool start(const std::string& name, int gyros = 2) {
    const std::string dir = ::testing::TempDir() + name + "-" + std::to_string(getpid());
    can_socket = dir + ".sock";
    out = dir + ".simrig.out";
    err = dir + ".simrig.err";
    config_path = dir + ".station.toml";
    std::vector<std::string> args{kSimrigBin,     "--gyros", std::to_string(gyros), "--seed", "5",
                                  "--can-socket", can_socket};
    args.insert(args.end(), extra_args.begin(), extra_args.end());
    pid = spawn_process(args, out, err);
    const std::string last_serial = "SIM-000" + std::to_string(gyros);
    if (!wait_until([&] { return slurp(out).find(last_serial) != std::string::npos; },
                    std::chrono::seconds(5)))
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the slot's last lines
    std::ofstream(config_path) << slurp(out);
    return true;
  }
  void stop() {
    if (pid > 0) {
      kill(pid, SIGTERM);
      wait_bounded(pid, std::chrono::seconds(5));
      pid = -1;
    }
  }
  ~SimrigProcess() { stop(); }
};

}  // namespace station::testing_support
