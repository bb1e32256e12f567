// Run progress (issue 23): the text an operator reads, the log's pace, and systemd's status line
// over a real notify socket.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "drivers/common/unique_fd.hpp"
#include "station/cli/progress_display.hpp"

namespace station {
namespace {

TickReport tick(double t_s, bool recording) {
  TickReport r;
  r.t_s = t_s;
  r.run_id = 3;
  r.step_index = 3;
  r.steps = 6;
  r.step_label = "heat to +70 C at 10 C/h";
  r.air_c = 12.34;
  r.chamber = drivers::ChamberState{};
  r.chamber->setpoint_c = 12.5;
  r.recording = recording;
  return r;
}

TEST(ProgressDisplay, TextNamesStepTargetAirSetpointAndBins) {
  EXPECT_EQ(ProgressDisplay::text(tick(9000, true), 14),
            "run 3  2.50 h  step 4/6 heat to +70 C at 10 C/h  air 12.3 C  setpoint 12.5 C  "
            "recording, 14 bins of 600 s");
}

TEST(ProgressDisplay, ALogGetsALineEveryIntervalAndStatusEveryTick) {
  char* buf = nullptr;
  std::size_t len = 0;
  std::FILE* mem = open_memstream(&buf, &len);
  ASSERT_NE(mem, nullptr);
  int statuses = 0;
  std::string last;
  {
    ProgressDisplay p(mem, false, 300.0, 600.0, [&](const std::string& s) {
      ++statuses;
      last = s;
    });
    for (int t = 0; t < 1200; ++t) p.tick(tick(t, true));
    p.finish();
  }
  std::fclose(mem);
  const std::string out(buf, len);
  std::free(buf);
  EXPECT_EQ(statuses, 1200);
  // t = 0, 300, 600, 900: four lines; the bins count recorded ticks / 600.
  std::size_t lines = 0;
  for (char c : out) lines += c == '\n';
  EXPECT_EQ(lines, 4u) << out;
  EXPECT_NE(last.find("recording, 2 bins"), std::string::npos) << last;
}

TEST(ProgressDisplay, ATerminalLineIsRedrawnInPlace) {
  char* buf = nullptr;
  std::size_t len = 0;
  std::FILE* mem = open_memstream(&buf, &len);
  ProgressDisplay p(mem, true, 300.0, 600.0, {});
  p.tick(tick(1, false));
  p.tick(tick(2, false));
  p.finish();
  std::fclose(mem);
  const std::string out(buf, len);
  std::free(buf);
  EXPECT_EQ(out.rfind("\r\x1b[2K", 0), 0u);
  EXPECT_EQ(out.back(), '\n');
  std::size_t newlines = 0;
  for (char c : out) newlines += c == '\n';
  EXPECT_EQ(newlines, 1u);
}

// What `systemctl status` shows: the daemon's STATUS= datagram on $NOTIFY_SOCKET (sd_notify(3)).
TEST(ProgressDisplay, StatusGoesToTheNotifySocket) {
  const std::string path = testing::TempDir() + "notify-" + std::to_string(::getpid());
  ::unlink(path.c_str());
  drivers::UniqueFd fd(::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  ASSERT_TRUE(fd.valid());
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(path.size(), sizeof(addr.sun_path));
  path.copy(addr.sun_path, path.size());
  ASSERT_EQ(::bind(fd.get(), reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
  ::setenv("NOTIFY_SOCKET", path.c_str(), 1);
  notify_status("run 3  2.50 h  step 4/6");
  ::unsetenv("NOTIFY_SOCKET");
  timeval tv{2, 0};
  ::setsockopt(fd.get(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  std::array<char, 512> msg{};
  const ssize_t n = ::recv(fd.get(), msg.data(), msg.size(), 0);
  ASSERT_GT(n, 0);
  EXPECT_EQ(std::string(msg.data(), static_cast<std::size_t>(n)), "STATUS=run 3  2.50 h  step 4/6");
  ::unlink(path.c_str());
}

}  // namespace
}  // namespace station
