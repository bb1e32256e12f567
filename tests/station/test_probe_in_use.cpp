// `station probe` while a station process runs the rig (issue 35, "Tools that do not disturb a
// run"): it takes the device locks `run` and `serve` hold, reads no device when it cannot, and
// prints what the running station sees (GET /api/status); --force refuses then. On the simrig
// of a person's desk, over real sockets, with real processes.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <thread>

#include "station/http/status_client.hpp"
#include "tests/station/rig_process.hpp"

namespace {

namespace ts = station::testing_support;
using namespace std::chrono_literals;

bool has(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

// A one-connection HTTP server on 127.0.0.1 that answers the first request with `head` and then
// `body` one byte per 200 ms (a dripping answer) or at once; the hostile station of the review.
class FakeStation {
 public:
  FakeStation(std::string head, std::string body, bool drip)
      : fd_(socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    listen(fd_, 1);
    getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this, head = std::move(head), body = std::move(body), drip] {
      const int c = accept(fd_, nullptr, nullptr);
      if (c < 0) return;
      char buf[4096];
      (void)!read(c, buf, sizeof buf);
      bool ok = send(c, head.data(), head.size(), MSG_NOSIGNAL) > 0;
      for (std::size_t i = 0; ok && i < body.size(); i += drip ? 1 : body.size()) {
        ok = send(c, body.data() + i, drip ? 1 : body.size(), MSG_NOSIGNAL) > 0;
        if (drip) std::this_thread::sleep_for(200ms);
      }
      close(c);
    });
  }
  ~FakeStation() {
    shutdown(fd_, SHUT_RDWR);
    thread_.join();
    close(fd_);
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }

 private:
  int fd_;
  int port_ = 0;
  std::thread thread_;
};

std::string ok_head(std::size_t length) {
  return "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: " +
         std::to_string(length) + "\r\n\r\n";
}

// The port `serve --http 127.0.0.1:0` printed on stdout ("http://127.0.0.1:PORT/").
std::string served_port(const std::string& out_file) {
  const std::string text = ts::slurp(out_file);
  const auto at = text.find("127.0.0.1:");
  if (at == std::string::npos) return {};
  return text.substr(at + 10, text.find_first_not_of("0123456789", at + 10) - at - 10);
}

TEST(ProbeInUse, AsksTheRunningStationAndTouchesNoDevice) {
  ts::SimrigProcess rig;
  ASSERT_TRUE(rig.start("probe-in-use")) << ts::slurp(rig.err);
  const std::string db = ::testing::TempDir() + "probe-in-use-" + std::to_string(getpid()) + ".db";
  std::remove(db.c_str());
  const pid_t serve = ts::spawn_process(
      {ts::kStationBin, "serve", "--config", rig.config_path, "--db", db, "--http", "127.0.0.1:0"},
      db + ".serve.out", db + ".serve.err");
  std::string port;
  ASSERT_TRUE(ts::wait_until([&] { return !(port = served_port(db + ".serve.out")).empty(); }, 20s))
      << ts::slurp(db + ".serve.err");
  // Idle, serve reads the rig every second: wait for its first reading.
  ASSERT_TRUE(ts::wait_until(
      [&] {
        const auto a = station::http::fetch_status("127.0.0.1:" + port, 1.0);
        return a.status && (*a.status)["chamber"].is_object();
      },
      20s));
  const std::string connections_before = ts::slurp(rig.err);

  const auto asked = ts::station_command(
      "probe --config " + rig.config_path + " --http 127.0.0.1:" + port, "probe-in-use");
  EXPECT_EQ(asked.status, 0) << asked.out;
  EXPECT_TRUE(has(asked.out, "rig in use: ")) << asked.out;
  EXPECT_TRUE(has(asked.out, "(pid " + std::to_string(serve) + ")")) << asked.out;
  EXPECT_TRUE(has(asked.out, "http://127.0.0.1:" + port + "/api/status")) << asked.out;
  EXPECT_TRUE(has(asked.out, "what 'simrig' sees: state idle")) << asked.out;
  // Idle, serve reads no counter board (the gyros' bus is a run's): probe names the slots so.
  EXPECT_TRUE(has(asked.out, "slot SIM-0002")) << asked.out;
  EXPECT_TRUE(has(asked.out, "node 2: counter boards are read during a run only")) << asked.out;
  EXPECT_FALSE(has(asked.out, "failed")) << asked.out;
  // No second station on simrig's CAN bus: simrig logs every station that connects.
  EXPECT_EQ(ts::slurp(rig.err), connections_before);

  const auto json = ts::station_command(
      "probe --json --config " + rig.config_path + " --http 127.0.0.1:" + port, "probe-in-use-j");
  EXPECT_EQ(json.status, 0) << json.out;
  const auto j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["devices_read"], false);
  EXPECT_EQ(j["status"]["state"], "idle");
  EXPECT_EQ(j["status"]["rig_slots"].size(), 2u);

  const auto forced =
      ts::station_command("probe --force --config " + rig.config_path, "probe-in-use-f");
  EXPECT_EQ(forced.status, 2) << forced.out;
  EXPECT_TRUE(has(forced.out, "refusing to touch a rig in use")) << forced.out;
  EXPECT_TRUE(has(forced.out, "(pid " + std::to_string(serve) + ")")) << forced.out;

  // Nobody answers where the probe asks: it says so, names the holder and reads nothing.
  const auto unanswered = ts::station_command(
      "probe --config " + rig.config_path + " --http 127.0.0.1:1", "probe-in-use-n");
  EXPECT_EQ(unanswered.status, 2) << unanswered.out;
  EXPECT_TRUE(has(unanswered.out, "no usable answer: ")) << unanswered.out;
  EXPECT_EQ(ts::slurp(rig.err), connections_before);

  // A hostile or wrong answer is no answer (exit 2), within the probe's 2 s for the whole of it.
  const std::string other = R"({"state": "idle", "station": "simrig", "pid": 1, "slots": []})";
  const std::string wrong_type = R"({"state": 1, "chamber": {"air_c": "x"}, "fault": {}})";
  const struct {
    const char* what;
    std::string head, body;
    bool drip;
    const char* says;
  } hostile[] = {
      {"a dripping answer", ok_head(100), std::string(100, ' '), true, "no whole answer within"},
      {"another station", ok_head(other.size()), other, false, "not the rig's holder (pid"},
      {"an array", ok_head(7), "[1,2,3]", false, "not a JSON object"},
      {"fields of other types", ok_head(wrong_type.size()), wrong_type, false,
       "not a station's status"},
      {"bytes that are not UTF-8", "HTTP/1.1 500 Oops\r\nContent-Length: 2\r\n\r\n", "\xff\xfe",
       false, "HTTP 500"}};
  for (const auto& h : hostile) {
    SCOPED_TRACE(h.what);
    for (const std::string json : {"", " --json"}) {  // a fake answers one connection
      FakeStation fake(h.head, h.body, h.drip);
      const auto o = ts::station_command(
          "probe" + json + " --config " + rig.config_path + " --http " + fake.address(),
          "probe-in-use-h");
      EXPECT_EQ(o.status, 2) << o.out;
      EXPECT_TRUE(has(o.out, h.says)) << o.out;
    }
  }

  kill(serve, SIGTERM);
  ASSERT_NE(ts::wait_bounded(serve, 20s), -1);
  // Nothing runs: probe --force (and probe) read the devices themselves.
  const auto free =
      ts::station_command("probe --force --config " + rig.config_path, "probe-in-use-free");
  EXPECT_EQ(free.status, 0) << free.out;
  EXPECT_TRUE(has(free.out, "all devices answered")) << free.out;
}

}  // namespace
