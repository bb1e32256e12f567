// Issue 34 point 5: a PostgreSQL backend that stops answering (SIGSTOP: its connection stays up)
// or a reply that never comes. Every call has a client deadline: the pass, `serve`'s forwarding
// thread and `station sync` end in a timeout naming the call instead of waiting for ever, the
// thread says it is waiting while it waits and stops at once when asked; after SIGCONT every row
// arrives exactly once, and a COMMIT whose answer was lost is settled by the idempotent resend.
// The server is the throw-away PostgreSQL 15; a proxy (pg_proxy.hpp) passes the real bytes and
// only says when the forwarder starts a COPY (the backend is frozen then) or drops one answer.
#include <gtest/gtest.h>
#include <signal.h>

#include <condition_variable>
#include <cstdio>
#include <functional>
#include <mutex>
#include <thread>

#include "station/fleet/forwarder_thread.hpp"
#include "tests/fleet/fleet_fixture.hpp"
#include "tests/fleet/pg_proxy.hpp"

namespace {

namespace fleet = station::fleet;
using station::testing_support::FleetTest;
using station::testing_support::PgProxy;
using station::testing_support::query_message;

const std::string kStation = std::string(STATION_BINARY_DIR) + "/station/station";

std::int64_t server_count(const std::string& table) {
  fleet::PgConnection pg(FleetTest::target());
  return pg.exec("SELECT count(*) FROM " + table).integer(0, 0);
}

std::int64_t local_count(const std::string& db, const std::string& table) {
  station::Database d(db, station::OpenMode::read_only);
  auto st = d.prepare("SELECT count(*) FROM " + table);
  st.step();
  return st.column_int(0);
}

/// The backend of the station's connection (application_name gyro-station) on the test's
/// database, stopped with SIGSTOP (its socket stays open; it reads and answers nothing).
class FrozenBackend {
 public:
  ~FrozenBackend() { thaw(); }
  void freeze() {
    fleet::PgConnection pg(FleetTest::target());
    auto r = pg.exec(
        "SELECT pid FROM pg_stat_activity WHERE application_name = 'gyro-station' AND datname = "
        "current_database() AND pid <> pg_backend_pid()");
    if (r.rows() != 1) throw std::runtime_error("no single station backend to freeze");
    pid_ = static_cast<pid_t>(r.integer(0, 0));
    ::kill(pid_, SIGSTOP);
  }
  /// Resumes it; true when it was frozen until now.
  bool thaw() {
    std::lock_guard lock(mu_);
    if (pid_ <= 0) return false;
    ::kill(pid_, SIGCONT);
    pid_ = 0;
    return true;
  }
  bool frozen() const { return pid_ > 0; }

 private:
  std::atomic<pid_t> pid_{0};
  std::mutex mu_;
};

/// Freezes the backend when the forwarder's first COPY of events starts (mid-item: the run's own
/// row is staged, nothing committed).
void freeze_at_copy(PgProxy& proxy, FrozenBackend& backend) {
  proxy.on_client([&backend](std::string_view bytes) {
    if (!backend.frozen() && bytes.find("COPY events (") != std::string_view::npos)
      backend.freeze();
  });
}

/// Runs `rescue` after `after_s` unless destroyed first (resumes the backend, cuts the link): a
/// code that waits for the server for ever gets its answer then, so a test of it fails instead of
/// hanging, and the test sees the order of things, not their durations.
class Watchdog {
 public:
  Watchdog(double after_s, std::function<void()> rescue)
      : thread_([this, after_s, rescue = std::move(rescue)] {
          std::unique_lock lock(mu_);
          if (!cv_.wait_for(lock, std::chrono::duration<double>(after_s), [this] { return done_; }))
            rescue();
        }) {}
  Watchdog(FrozenBackend& b, double after_s) : Watchdog(after_s, [&b] { b.thaw(); }) {}
  ~Watchdog() {
    {
      std::lock_guard lock(mu_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

class FleetDeadline : public FleetTest {
 protected:
  /// Through the proxy, with a server statement timeout of 1 s (a client deadline of 2 s).
  fleet::PgTarget proxied(const PgProxy& proxy, double statement_timeout_s = 1.0) const {
    return {proxy.url(db_), {}, fleet::kPgConnectTimeoutS, statement_timeout_s};
  }
  static fleet::ForwardOptions options() { return {.samples = false, .station = "test"}; }
};

TEST_F(FleetDeadline, AFrozenBackendMidCopyTimesOutThenEveryRowArrivesOnce) {
  const auto db = simulated_station("fleet_frozen_pass", 1, 41);
  PgProxy proxy(server_->dir());
  FrozenBackend backend;
  freeze_at_copy(proxy, backend);
  fleet::Forwarder f(db, proxied(proxy), options());
  std::string error;
  {
    Watchdog resume(backend, 30);  // the code before issue 34 waits until then
    try {
      f.pass();
    } catch (const fleet::PgError& e) {
      error = e.what();
    }
    EXPECT_TRUE(backend.frozen()) << "the pass returned only once the backend was resumed";
  }
  EXPECT_NE(error.find("timed out"), std::string::npos) << error;
  EXPECT_NE(error.find("COPY events ("), std::string::npos) << "names the call: " << error;
  EXPECT_NE(error.find(proxy.dir()), std::string::npos) << "names the server: " << error;
  EXPECT_EQ(server_count("runs"), 0) << "nothing of the cut item was committed";
  EXPECT_TRUE(backend.thaw());
  const auto after = forward_all(db, false);
  EXPECT_EQ(after.failed, 0) << after.last_error;
  EXPECT_EQ(server_count("events"), local_count(db, "events"));
  EXPECT_EQ(server_count("runs"), local_count(db, "runs"));
  EXPECT_EQ(server_count("fits"), local_count(db, "fits"));
  EXPECT_EQ(fleet::Forwarder(db, target(), options()).backlog().items, 0);
}

// The server commits; its answer is lost. The client cannot know: it times out, nothing is
// acknowledged, and the next pass resends the item, which the idempotent merge writes nothing of.
TEST_F(FleetDeadline, ACommitWhoseAnswerIsLostIsSettledByTheResend) {
  const auto db = simulated_station("fleet_lost_commit", 1, 42);
  PgProxy proxy(server_->dir());
  proxy.swallow_replies_after(query_message("COMMIT"));
  fleet::Forwarder f(db, proxied(proxy), options());
  {
    Watchdog cut(30, [&proxy] { proxy.cut(); });  // the code before issue 34 waits until then
    EXPECT_THROW(f.pass(1), fleet::PgTimeout);
  }
  ASSERT_EQ(server_count("runs"), 1) << "the server committed the run";
  const std::int64_t events = server_count("events");
  EXPECT_EQ(events, local_count(db, "events"));
  EXPECT_GT(fleet::Forwarder(db, target(), options()).backlog().runs, 0)
      << "acknowledged without the server's answer";
  const auto resend = forward_all(db, false);
  EXPECT_EQ(resend.failed, 0) << resend.last_error;
  EXPECT_EQ(resend.appended, 0) << "events sent twice";
  EXPECT_EQ(server_count("events"), events);
  EXPECT_EQ(server_count("runs"), 1);
  EXPECT_EQ(server_count("fits"), local_count(db, "fits"));
  EXPECT_EQ(fleet::Forwarder(db, target(), options()).backlog().items, 0);
}

// serve's thread: while the backend is frozen its status says it waits (with the backlog), and a
// stop ends it while the backend is still frozen (the deadline is long: the stop must do it).
TEST_F(FleetDeadline, TheThreadSaysItWaitsAndStopsWhileTheBackendIsFrozen) {
  const auto db = simulated_station("fleet_frozen_thread", 1, 43);
  PgProxy proxy(server_->dir());
  FrozenBackend backend;
  freeze_at_copy(proxy, backend);
  std::mutex mu;
  std::condition_variable cv;
  std::optional<fleet::ForwarderStatus> waiting;
  auto thread = std::make_unique<fleet::ForwarderThread>(
      db, proxied(proxy, 300), options(), 0.5, [&](const fleet::ForwarderStatus& s) {
        std::lock_guard lock(mu);
        if (s.state == "waiting on server" && !waiting) waiting = s;
        cv.notify_all();
      });
  {
    std::unique_lock lock(mu);
    cv.wait_for(lock, std::chrono::seconds(60), [&] { return waiting.has_value(); });
  }
  ASSERT_TRUE(waiting.has_value()) << "the status never said it waits on the server";
  EXPECT_GT(waiting->backlog.rows, 0) << "the backlog counted while waiting";
  EXPECT_NE(waiting->waiting_for.find("COPY"), std::string::npos) << waiting->waiting_for;
  EXPECT_GE(waiting->waiting_s, fleet::kPgSlowCallS - 1);
  EXPECT_EQ(waiting->to_json()["state"], "waiting on server");
  {
    Watchdog resume(backend, 20);  // the code before issue 34 stops only once resumed
    thread.reset();
    EXPECT_TRUE(backend.frozen()) << "the stop waited for the frozen backend";
  }
  backend.thaw();
  EXPECT_EQ(forward_all(db, false).failed, 0);
  EXPECT_EQ(server_count("events"), local_count(db, "events"));
}

std::string capture(const std::string& cmd, int& rc) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  rc = pclose(p);
  return out;
}

TEST_F(FleetDeadline, SyncEndsWithTheCallThatTimedOutThenSendsEveryRowOnce) {
  const auto db = simulated_station("fleet_frozen_sync", 1, 44);
  PgProxy proxy(server_->dir());
  FrozenBackend backend;
  freeze_at_copy(proxy, backend);
  int rc = 0;
  std::string out;
  {
    Watchdog resume(backend, 30);
    out = capture(
        kStation + " sync --timeout-s 1 --db " + db + " --pg '" + proxy.url(db_) + "' 2>&1", rc);
    EXPECT_TRUE(backend.frozen()) << "sync ended only once the backend was resumed: " << out;
  }
  EXPECT_EQ(WEXITSTATUS(rc), 1) << out;
  EXPECT_NE(out.find("station: error: PostgreSQL " + proxy.dir()), std::string::npos) << out;
  EXPECT_NE(out.find("COPY events ("), std::string::npos) << out;
  EXPECT_NE(out.find("timed out"), std::string::npos) << out;
  EXPECT_TRUE(backend.thaw());
  out = capture(kStation + " sync --json --db " + db + " --pg '" + target().url + "'", rc);
  ASSERT_EQ(WEXITSTATUS(rc), 0) << out;
  EXPECT_EQ(server_count("events"), local_count(db, "events"));
  EXPECT_EQ(server_count("runs"), local_count(db, "runs"));
}

}  // namespace
