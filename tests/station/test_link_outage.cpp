// The CAN link cut mid-run and restored: the daemon reconnects on its own, the outage is one
// event with the ticks it cost, the first latch after it is either proven continuous (and then
// exact) or re-baselined (board reset), and a run that lost too much of its record window ends
// 'incomplete' with its fit saying so. Production sequencer on the simulated clock; the counter
// boards sit behind a unix socket the test cuts.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "compensation/earth_rate.hpp"
#include "sim_devices/sim_clock.hpp"
#include "sim_devices/sim_world.hpp"
#include "station/daemon/rig_probe.hpp"
#include "station/daemon/sequencer.hpp"
#include "station/store/calibration.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace sim = station::sim;
using station::testing_support::fresh_db;

// The world's gyros on counter boards behind a listening unix socket. A thread accepts the
// station (as simrig does); cut() drops it and stops listening, listen() comes back. Boards
// are built at connect time and stepped to the world's time, so at constant temperature a new
// board counts exactly as the old one would have (same seed, same steps): the board kept running.
class BoardServer {
 public:
  BoardServer(std::string path, const sim::SimWorldConfig& wc, std::vector<sim::SimGyro> gyros)
      : path_(std::move(path)), wc_(wc), gyros_(std::move(gyros)) {
    listen();
    thread_ = std::thread([this] { accept_loop(); });
  }
  ~BoardServer() {
    stop_ = true;
    thread_.join();
    cut();
  }
  void listen() {
    const std::lock_guard lock(m_);
    ::unlink(path_.c_str());
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path_.c_str(), sizeof addr.sun_path - 1);
    listen_fd_ = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    ASSERT_EQ(::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    ASSERT_EQ(::listen(listen_fd_, 4), 0);
  }
  // The station's connection closes and nothing listens: reconnects are refused.
  void cut() {
    const std::lock_guard lock(m_);
    bus_.reset();
    if (listen_fd_ >= 0) ::close(listen_fd_);
    listen_fd_ = -1;
    ::unlink(path_.c_str());
  }
  // The next boards start from zero counts and a zero clock (a restarted simulator).
  void reset_boards_on_next_connect() { reset_next_ = true; }
  void step(double t_s, double air_c) {
    const std::lock_guard lock(m_);
    now_s_ = t_s;
    air_c_ = air_c;
    if (bus_) bus_->step_to(t_s, air_c);
  }

 private:
  void accept_loop() {
    while (!stop_) {
      {
        const std::lock_guard lock(m_);
        pollfd p{listen_fd_, POLLIN, 0};
        if (listen_fd_ >= 0 && ::poll(&p, 1, 0) == 1) {
          const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
          if (fd >= 0) start_bus(fd);
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  void start_bus(int fd) {
    bus_ = std::make_unique<sim::CounterBoardBus>(fd);
    for (std::size_t i = 0; i < gyros_.size(); ++i) {
      sim::BoardConfig b;  // as SimWorld::add_boards builds them
      b.node = gyros_[i].node;
      b.gyro.coefficients = gyros_[i].truth;
      b.gyro.thermal = sim::sim_thermal(wc_.preset);
      b.gyro.thermal.initial_c = wc_.initial_c;
      b.gyro.earth_rate_dph = wc_.earth_rate_dph;
      b.gyro.pulse_weight_arcsec = gyros_[i].pulse_weight_arcsec;
      b.gyro.seed = wc_.seed * 7919u + i + 1;
      b.board_time_offset_us = static_cast<std::uint32_t>(i * 123457u);
      if (reset_next_) {  // counts and clock read about zero now
        b.initial_up = b.initial_down = 0u - static_cast<std::uint32_t>(2e4 * now_s_);
        b.board_time_offset_us = 1000u - static_cast<std::uint32_t>(std::llround(now_s_ * 1e6));
      }
      bus_->add_board(b);
    }
    reset_next_ = false;
    bus_->step_to(now_s_, air_c_);
    bus_->start();
  }

  std::string path_;
  sim::SimWorldConfig wc_;
  std::vector<sim::SimGyro> gyros_;
  std::mutex m_;
  std::unique_ptr<sim::CounterBoardBus> bus_;
  int listen_fd_ = -1;
  double now_s_ = 0, air_c_ = 25;
  bool reset_next_ = false;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Constant 25 C for the first 60 s (the cut falls there), then a ramp to 45 C and a soak, so the
// fit has something to fit. bin_s 60 and a record window of ~1000 ticks.
constexpr const char* kProtocol = R"(name = "outage"
[[step]]
type = "record_start"
[[step]]
type = "hold"
duration_s = 60
[[step]]
type = "set_temperature"
setpoint_c = 45.0
ramp_c_per_h = 180.0
tolerance_c = 0.5
[[step]]
type = "hold"
duration_s = 500
[[step]]
type = "record_stop"
)";

constexpr double kCutS = 20;      // the link drops at this tick
constexpr double kRestoreS = 26;  // the boards listen again from this tick
// Reconnect attempts at 21, 22, 23, 25, 29 s (0.5, 1, 2, 4 s back-off): 29 is the first that
// finds the boards, so ticks 20..28 are lost.
constexpr double kBackS = 29;
constexpr std::int64_t kLost = 9;

struct RunResult {
  std::string state;
  std::map<std::string, std::vector<station::SampleRow>> samples;         // per serial, all ticks
  std::vector<std::tuple<std::string, std::string, std::string>> events;  // source, kind, data
  std::vector<std::string> fit_warnings;                                  // SIM-0001's
  std::vector<std::string> refit_warnings;  // SIM-0001 fitted again later (`station fit`)
};

enum class Cut { none, link, link_and_board_reset };

RunResult run_rig(Cut cut, const std::string& name) {
  const std::string dir = ::testing::TempDir();
  const std::string sock = dir + name + "-" + std::to_string(getpid()) + ".sock";
  const std::string proto = dir + name + "-" + std::to_string(getpid()) + ".toml";
  std::ofstream(proto) << kProtocol;
  sim::SimWorldConfig wc;
  wc.gyros = 2;
  wc.seed = 3;
  wc.earth_rate_dph = station::compensation::earth_rate_along_axis_dph(39.9, {0, 0, 1});
  sim::SimWorld world(wc);
  BoardServer boards(sock, wc, world.gyros());
  std::string text = fmt::format(
      "[station]\nlatitude_deg = 39.9\nbin_s = 60\nmax_lost_share = 0.005\n"
      "[chamber]\nendpoint = \"{}\"\nmodel = \"generic_plc\"\n"
      "[can]\ntransport = \"unix:{}\"\ntick_timeout_ms = 900\n",
      world.chamber_endpoint(), sock);
  for (const auto& g : world.gyros())
    text += fmt::format("[[slot]]\nnode = {}\nserial = \"{}\"\npulse_weight_arcsec = {}\n", g.node,
                        g.serial, g.pulse_weight_arcsec);
  const auto config = station::parse_station_config(text, name + ".toml");
  const auto db = fresh_db(name);
  station::Store store(db);
  store.set_ticks_per_commit(60);
  sim::SimClock clock;
  station::RigOptions ro;
  ro.clock = &clock;  // reconnects happen at the same simulated ticks every time
  station::Rig rig = station::build_rig(config, ro);
  const auto unreachable = station::unreachable_devices(config, rig);  // as `run` does
  EXPECT_TRUE(unreachable.empty()) << ::testing::PrintToString(unreachable);
  station::SequencerOptions so;
  so.before_tick = [&](double t_s) {
    world.advance_to(t_s);
    if (cut != Cut::none && t_s == kCutS) boards.cut();
    if (cut == Cut::link_and_board_reset && t_s == kCutS) boards.reset_boards_on_next_connect();
    if (cut != Cut::none && t_s == kRestoreS) boards.listen();
    boards.step(t_s, world.chamber().air_c());
  };
  station::Sequencer seq(config, station::load_protocol(proto), rig, store, clock, so);
  const auto out = seq.run();
  RunResult r;
  r.state = station::to_string(out.state);
  for (const auto& g : world.gyros())
    r.samples[g.serial] = store.samples(out.run_id, g.serial, false);
  auto st = store.db().prepare(
      "SELECT source, kind, coalesce(data_json, '') FROM events WHERE run_id = ? ORDER BY id");
  st.bind(1, out.run_id);
  while (st.step()) r.events.emplace_back(st.column_text(0), st.column_text(1), st.column_text(2));
  if (const auto fit = store.latest_fit("SIM-0001")) r.fit_warnings = fit->fit.warnings;
  const station::compensation::ModelSpec spec{
      {station::compensation::Term::dT, station::compensation::Term::gradT}, 25.0};
  r.refit_warnings = station::fit_serial(store, "SIM-0001", {out.run_id}, spec).fit.warnings;
  return r;
}

const RunResult& undisturbed() {
  static const RunResult r = run_rig(Cut::none, "undisturbed");
  return r;
}

int count(const RunResult& r, const std::string& kind) {
  int n = 0;
  for (const auto& [source, k, data] : r.events) n += k == kind ? 1 : 0;
  return n;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "; ";
  return s;
}

}  // namespace

TEST(LinkOutage, UndisturbedRunHasNoOutage) {
  const auto& u = undisturbed();
  EXPECT_EQ(u.state, "completed");
  EXPECT_EQ(count(u, "outage"), 0);
  EXPECT_EQ(count(u, "outage_start"), 0);
  for (const auto& [serial, rows] : u.samples) {
    ASSERT_GT(rows.size(), 900u);
    EXPECT_FALSE(rows.front().rate_dph.has_value());  // the first latch is the baseline
    for (std::size_t k = 1; k < rows.size(); ++k)
      EXPECT_TRUE(rows[k].rate_dph.has_value()) << serial << " t " << rows[k].t_s;
  }
  EXPECT_EQ(joined(u.fit_warnings).find("incomplete"), std::string::npos);
  EXPECT_EQ(joined(u.refit_warnings).find("incomplete"), std::string::npos);
}

TEST(LinkOutage, CutLinkReconnectsIsOneOutageAndTheGapIsExact) {
  const auto& u = undisturbed();
  const auto r = run_rig(Cut::link, "cut");
  // One outage of the bus, with its data; the boards behind it have none of their own.
  ASSERT_EQ(count(r, "outage"), 1) << r.events.size();
  EXPECT_EQ(count(r, "outage_start"), 1);
  EXPECT_EQ(count(r, "board_reset"), 0);
  for (const auto& [source, kind, data] : r.events) {
    if (kind != "outage") continue;
    EXPECT_EQ(source, "can");
    const auto j = nlohmann::json::parse(data);
    EXPECT_EQ(j["device"], "can");
    EXPECT_EQ(j["start_s"], kCutS);
    EXPECT_EQ(j["end_s"], kBackS);
    EXPECT_EQ(j["ticks_lost"], kLost);
    EXPECT_EQ(j["ended"], "answered");  // the bus came back (not closed at the run's end)
  }
  for (const auto& [serial, rows] : r.samples) {
    SCOPED_TRACE(serial);
    const auto& base = u.samples.at(serial);
    ASSERT_EQ(rows.size(), base.size());
    std::int64_t gap_pulses = 0;  // what the undisturbed run counted over the outage
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const double t = rows[k].t_s;
      if (t >= kCutS && t <= kBackS) gap_pulses += *base[k].net_pulses;
      if (t >= kCutS && t < kBackS) {
        EXPECT_FALSE(rows[k].rate_dph.has_value()) << t;
      } else if (t == kBackS) {
        // The board clock vouches for the gap: one delta over all of it, nothing lost.
        EXPECT_EQ(*rows[k].net_pulses, gap_pulses);
        EXPECT_NEAR(*rows[k].interval_s, kBackS - kCutS + 1, 1e-9);
      } else {
        EXPECT_EQ(rows[k].rate_dph, base[k].rate_dph) << t;  // bit for bit
      }
    }
  }
  // 9 of ~1000 record-window ticks is above max_lost_share = 0.5 %.
  EXPECT_EQ(r.state, "incomplete");
  EXPECT_EQ(count(r, "incomplete"), 2);
  EXPECT_NE(joined(r.fit_warnings).find("run 1 incomplete: SIM-0001 has no rate for"),
            std::string::npos)
      << joined(r.fit_warnings);
  EXPECT_NE(joined(r.refit_warnings).find("run 1 ended incomplete"), std::string::npos)
      << joined(r.refit_warnings);
}

// simrig restarted: the boards come back with counters and clock from zero. The first latch is
// reported as a reset and re-baselined (the old code stored ~2^32 pulses as one interval); the
// next ones are the undisturbed run's, exactly.
TEST(LinkOutage, BoardsResetDuringTheOutageAreReportedAndRebaselined) {
  const auto& u = undisturbed();
  const auto r = run_rig(Cut::link_and_board_reset, "reset");
  EXPECT_EQ(count(r, "outage"), 1);
  EXPECT_EQ(count(r, "board_reset"), 2);  // one per board
  for (const auto& [serial, rows] : r.samples) {
    SCOPED_TRACE(serial);
    const auto& base = u.samples.at(serial);
    ASSERT_EQ(rows.size(), base.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const double t = rows[k].t_s;
      if (t >= kCutS && t <= kBackS)
        EXPECT_FALSE(rows[k].rate_dph.has_value()) << t;
      else
        EXPECT_EQ(rows[k].rate_dph, base[k].rate_dph) << t;
    }
  }
  EXPECT_EQ(r.state, "incomplete");
}
