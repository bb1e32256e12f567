// The replay's own lines on stderr (replay_narration.hpp).
#include "station/session/replay_narration.hpp"

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <spdlog/pattern_formatter.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "station/common/input_error.hpp"
#include "station/common/logging.hpp"

namespace station {

namespace {

std::time_t parse_utc(const std::string& text) {
  std::tm tm{};
  int n = 0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2dT%2d:%2d:%2dZ%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
                  &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &n) != 6 ||
      static_cast<std::size_t>(n) != text.size() || text.size() != 20 || tm.tm_mon < 1 ||
      tm.tm_mon > 12 || tm.tm_mday < 1 || tm.tm_mday > 31 || tm.tm_hour > 23 || tm.tm_min > 59 ||
      tm.tm_sec > 60)
    throw InputError(fmt::format("started_utc '{}': not YYYY-MM-DDTHH:MM:SSZ", text));
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return timegm(&tm);
}

// The log line of the usual pattern without the wall time ("%Y-%m-%dT%H:%M:%S.%e", logging.cpp).
constexpr const char* kReplayedPattern = "replayed, recorded %* %^%l%$ [%n] %v";
constexpr const char* kLivePattern = "%Y-%m-%dT%H:%M:%S.%e %^%l%$ [%n] %v";

}  // namespace

std::string utc_plus(const std::string& started_utc, double t_s) {
  if (started_utc.empty()) return fmt::format("at t = {:.0f} s", std::max(t_s, 0.0));
  const auto t = std::chrono::system_clock::from_time_t(parse_utc(started_utc)) +
                 std::chrono::seconds(std::llround(std::max(t_s, 0.0)));
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", std::chrono::floor<std::chrono::seconds>(t));
}

struct ReplayNarration::Stamp {
  std::string started_utc;
  std::atomic<double> t_s{0};
};

namespace {

class StampFlag final : public spdlog::custom_flag_formatter {
 public:
  explicit StampFlag(std::shared_ptr<ReplayNarration::Stamp> s) : stamp_(std::move(s)) {}
  void format(const spdlog::details::log_msg&, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    const std::string text = utc_plus(stamp_->started_utc, stamp_->t_s.load());
    dest.append(text.data(), text.data() + text.size());
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<StampFlag>(stamp_);
  }

 private:
  std::shared_ptr<ReplayNarration::Stamp> stamp_;
};

}  // namespace

ReplayNarration::ReplayNarration(std::string started_utc, double last_tick_s, std::FILE* progress)
    : stamp_(std::make_shared<Stamp>()), last_tick_s_(last_tick_s), progress_(progress) {
  try {
    parse_utc(started_utc);  // a malformed header is named before anything replays
    stamp_->started_utc = std::move(started_utc);
  } catch (const InputError& e) {  // the replay goes on: its lines then carry the run time
    if (progress_ != nullptr)
      fmt::print(progress_, "replay: the session's {}; recorded lines carry their run time\n",
                 started_utc.empty() ? std::string("started_utc is missing") : e.what());
  }
  for (const char* name : {"seq", "chamber", "table", "can", "gpio", "db", "safety", "sim"})
    log(name);  // created now, so the pattern below reaches them all
  auto stamp = stamp_;
  spdlog::apply_all([&stamp](const std::shared_ptr<spdlog::logger>& l) {
    auto f = std::make_unique<spdlog::pattern_formatter>();
    f->add_flag<StampFlag>('*', stamp).set_pattern(kReplayedPattern);
    l->set_formatter(std::move(f));
  });
}

ReplayNarration::~ReplayNarration() {
  spdlog::apply_all([](const std::shared_ptr<spdlog::logger>& l) { l->set_pattern(kLivePattern); });
}

void ReplayNarration::at(double t_s) {
  stamp_->t_s.store(t_s);
  if (progress_ == nullptr || !(last_tick_s_ > 0)) return;
  const int tenths = static_cast<int>(std::floor(10.0 * std::min(t_s / last_tick_s_, 1.0)));
  if (tenths <= tenths_shown_) return;
  tenths_shown_ = tenths;
  fmt::print(progress_, "replay: {:3d} % (t = {:.0f} of {:.0f} s of the recorded run)\n",
             10 * tenths, t_s, last_tick_s_);
  std::fflush(progress_);
}

}  // namespace station
