// `station run --config` probes every configured device before it moves anything or touches the
// database: an unreachable one is exit 2 with one line per device, and no database file.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <string>

namespace {

struct Outcome {
  int status = -1;
  std::string err;
};

Outcome run_station(const std::string& args) {
  const std::string cmd =
      std::string(STATION_BINARY_DIR) + "/station/station " + args + " 2>&1 >/dev/null";
  Outcome o;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return o;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) o.err.append(buf.data(), n);
  const int raw = pclose(p);
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return o;
}

// A loopback TCP port nothing listens on (bound once by us, then released).
int closed_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

std::string config_file(const std::string& name, const std::string& chamber,
                        const std::string& table, const std::string& can) {
  const std::string path = ::testing::TempDir() + name + "-" + std::to_string(getpid()) + ".toml";
  std::ofstream(path) << "[station]\nlatitude_deg = 39.9\n[chamber]\nendpoint = \"" << chamber
                      << "\"\ntimeout_s = 0.2\n"
                      << (table.empty()
                              ? ""
                              : "[turntable]\nendpoint = \"" + table + "\"\ntimeout_s = 0.2\n")
                      << "[can]\ntransport = \"" << can
                      << "\"\n[[slot]]\nnode = 1\nserial = \"G1\"\n";
  return path;
}

int lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

}  // namespace

TEST(RunProbe, MissingSerialLineClosedPortAndBadFdAreRefusedBeforeTheDatabase) {
  const auto cfg = config_file("unreachable", "rtu:/dev/nonexistent",
                               "tcp://127.0.0.1:" + std::to_string(closed_port()), "fd:99999");
  const std::string db = ::testing::TempDir() + "never-" + std::to_string(getpid()) + ".db";
  std::remove(db.c_str());
  const auto o = run_station("run --config " + cfg + " --protocol paper --db " + db);
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_EQ(lines(o.err), 3) << o.err;  // one per unreachable device
  for (const char* what :
       {"chamber rtu:/dev/nonexistent", "turntable tcp://127.0.0.1:", "can fd:99999"})
    EXPECT_NE(o.err.find(what), std::string::npos) << what << "\n" << o.err;
  EXPECT_NE(o.err.find(cfg), std::string::npos) << "each line names the config file";
  EXPECT_NE(access(db.c_str(), F_OK), 0) << "the database was created";
}

TEST(RunProbe, UnresolvableHostAndMissingBusSocketAreRefused) {
  const std::string sock = ::testing::TempDir() + "no-bus-" + std::to_string(getpid()) + ".sock";
  const auto cfg =
      config_file("unresolvable", "tcp://no-such-probe-host.invalid:502", "", "unix:" + sock);
  const std::string db = ::testing::TempDir() + "never2-" + std::to_string(getpid()) + ".db";
  std::remove(db.c_str());
  const auto o = run_station("run --config " + cfg + " --protocol paper --db " + db);
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_EQ(lines(o.err), 2) << o.err;
  EXPECT_NE(o.err.find("chamber tcp://no-such-probe-host.invalid:502"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("can unix:" + sock), std::string::npos) << o.err;
  EXPECT_NE(access(db.c_str(), F_OK), 0) << "the database was created";
}
