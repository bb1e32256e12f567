// Counter-board simulator: latch on SYNC, answer with the shared wire codec, inject faults.
#include "sim_devices/counter_board_sim.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "drivers/counters/counter_frames.hpp"

namespace station::sim {

namespace wire = station::drivers::counters;

CounterBoardSim::CounterBoardSim(const BoardConfig& config)
    : config_(config),
      gyro_(config.gyro),
      fault_rng_(config.gyro.seed ^ 0x9E3779B97F4A7C15ULL),
      clock_offset_us_(config.board_time_offset_us) {
  if (config.node < 1 || config.node > wire::kMaxNode)
    throw std::invalid_argument("counter board sim: node out of range 1..16");
}

std::uint32_t CounterBoardSim::up_count() const {
  // Dither runs both counters; positive rotation adds to up only (schemas/can_frames.md).
  // Unsigned arithmetic is mod 2^32, as the board's 32-bit counters are.
  return config_.initial_up + static_cast<std::uint32_t>(gyro_.dither_pulses()) +
         static_cast<std::uint32_t>(gyro_.up_pulses()) - up_at_reset_;
}

std::uint32_t CounterBoardSim::down_count() const {
  return config_.initial_down + static_cast<std::uint32_t>(gyro_.dither_pulses()) +
         static_cast<std::uint32_t>(gyro_.down_pulses()) - down_at_reset_;
}

void CounterBoardSim::reset() {
  up_at_reset_ += up_count();
  down_at_reset_ += down_count();
  reset_at_s_ = gyro_.time_s();
  clock_offset_us_ = 0;  // the board clock starts again from 0
  reset_pending_ = true;
}

namespace {

// Takes one from a fault counter if it is positive (atomic against a concurrent setter).
bool take_one(std::atomic<int>& counter) {
  int n = counter.load();
  while (n > 0)
    if (counter.compare_exchange_weak(n, n - 1)) return true;
  return false;
}

}  // namespace

std::vector<BoardRecord> CounterBoardSim::on_sync(std::uint8_t latch_seq) {
  if (!answering_) return {};
  return apply_faults(build_frames(latch_seq));
}

std::vector<can_frame> CounterBoardSim::build_frames(std::uint8_t latch_seq) {
  const std::uint8_t node = config_.node;
  const int failed_temp = failed_temp_.load();  // one value for STATUS and TEMPS alike
  wire::StatusFrame st{node, latch_seq, extra_flags_.load(), 0, wire::kFollowsCounts};
  st.board_time_us = clock_offset_us_ +
                     static_cast<std::uint32_t>(std::llround((gyro_.time_s() - reset_at_s_) * 1e6));
  if (failed_temp >= 0) st.flags |= wire::kFlagTempSensorFault;
  if (std::exchange(reset_pending_, false)) st.flags |= wire::kFlagCounterReset;
  // An unpowered gyro: no laser discharge and no dither drive (can_frames.md, STATUS bits 0, 3).
  const bool powered = gyro_.powered();
  if (!powered) st.flags |= wire::kFlagLaserFault | wire::kFlagDitherFault;
  if (config_.temp_channels > 0) st.follows |= wire::kFollowsTemps;
  if (config_.send_discharge) st.follows |= wire::kFollowsDischarge;
  std::vector<can_frame> out{wire::encode(st),
                             wire::encode(wire::CountsFrame{node, up_count(), down_count()})};
  if (config_.temp_channels > 0) {
    wire::TempsFrame t{node, config_.temp_channels, {}};
    const double temps[] = {gyro_.temp_a_c(), gyro_.temp_b_c(), gyro_.temp_a_c(), 0.0};
    for (int i = 0; i < t.count && i < 4; ++i)
      t.centi_c[i] = i == failed_temp ? INT16_MIN  // the sensor's "no value" sentinel
                                      : static_cast<std::int16_t>(std::lround(temps[i] * 100));
    out.push_back(wire::encode(t));
  }
  if (config_.send_discharge)
    out.push_back(wire::encode(wire::DischargeFrame{
        node, powered ? config_.discharge_ua : std::array<std::uint32_t, 2>{}}));
  return out;
}

void corrupt_record(BoardRecord& r, CorruptKind kind, std::mt19937_64& rng) {
  switch (kind) {
    case CorruptKind::bad_dlc:
      r.frame.can_dlc = 3;
      return;
    case CorruptKind::short_record:
      r.short_record = true;
      return;
    case CorruptKind::garbage_id:
      r.frame.can_id = 0x700 + wire::node_bits(r.frame.can_id);
      for (auto& b : r.frame.data) b = static_cast<std::uint8_t>(rng());
      return;
  }
}

std::vector<BoardRecord> CounterBoardSim::apply_faults(const std::vector<can_frame>& frames) {
  std::vector<BoardRecord> out;
  for (const can_frame& f : frames) {
    if (take_one(drop_)) continue;
    BoardRecord r{f, false};
    if (take_one(corrupt_)) corrupt_record(r, corrupt_kind_.load(), fault_rng_);
    out.push_back(r);
    if (take_one(duplicate_)) out.push_back(r);
  }
  return out;
}

CounterBoardBus::CounterBoardBus(int fd) : fd_(fd) {}

CounterBoardBus::~CounterBoardBus() {
  stop();
  if (fd_ >= 0) ::close(fd_);
}

CounterBoardSim& CounterBoardBus::add_board(const BoardConfig& config) {
  const std::lock_guard lock(mutex_);
  boards_.push_back(std::make_unique<CounterBoardSim>(config));
  return *boards_.back();
}

CounterBoardSim& CounterBoardBus::board(std::uint8_t node) {
  const std::lock_guard lock(mutex_);
  for (auto& b : boards_)
    if (b->node() == node) return *b;
  throw std::out_of_range("counter board bus: no board with that node");
}

void CounterBoardBus::drop_frames(int n) {
  const std::lock_guard lock(mutex_);
  drop_ = n;
}

void CounterBoardBus::duplicate_frames(int n) {
  const std::lock_guard lock(mutex_);
  duplicate_ = n;
}

void CounterBoardBus::corrupt_frames(int n, CorruptKind kind) {
  const std::lock_guard lock(mutex_);
  corrupt_ = n;
  corrupt_kind_ = kind;
}

void CounterBoardBus::set_fault_rates(const BusFaultRates& rates, std::uint64_t seed) {
  const std::lock_guard lock(mutex_);
  rates_ = rates;
  rng_.seed(seed);
}

void CounterBoardBus::clear_faults() {
  const std::lock_guard lock(mutex_);
  drop_ = duplicate_ = corrupt_ = 0;
  rates_ = {};
}

void CounterBoardBus::reset_board(std::uint8_t node) {
  const std::lock_guard lock(mutex_);
  for (auto& b : boards_) {
    if (b->node() == node) return b->reset();
  }
  throw std::out_of_range("counter board bus: no board with that node");
}

void CounterBoardBus::set_powered(std::uint8_t node, bool on) {
  const std::lock_guard lock(mutex_);
  for (auto& b : boards_) {
    if (b->node() == node) return b->set_powered(on);
  }
  throw std::out_of_range("counter board bus: no board with that node");
}

std::vector<PowerUp> CounterBoardBus::power_ups(std::uint8_t node) {
  const std::lock_guard lock(mutex_);
  for (auto& b : boards_) {
    if (b->node() == node) return b->gyro().power_ups();
  }
  throw std::out_of_range("counter board bus: no board with that node");
}

// Called with mutex_ held: the counts first (deterministic), then the rates.
std::vector<BoardRecord> CounterBoardBus::apply_bus_faults(
    const std::vector<BoardRecord>& records) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<BoardRecord> out;
  for (BoardRecord r : records) {
    if (drop_ > 0 ? (--drop_, true) : u(rng_) < rates_.drop) continue;
    if (corrupt_ > 0) {
      --corrupt_;
      corrupt_record(r, corrupt_kind_, rng_);
    } else if (u(rng_) < rates_.corrupt) {
      corrupt_record(r, static_cast<CorruptKind>(rng_() % 3), rng_);
    }
    out.push_back(r);
    if (duplicate_ > 0 ? (--duplicate_, true) : u(rng_) < rates_.duplicate) out.push_back(r);
  }
  return out;
}

void CounterBoardBus::step_to(double sim_time_s, double chamber_air_c) {
  const std::lock_guard lock(mutex_);
  for (auto& b : boards_) b->step_to(sim_time_s, chamber_air_c);
}

int CounterBoardBus::service(std::chrono::milliseconds timeout) {
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0 || !(p.revents & POLLIN)) return 0;
  int syncs = 0;
  can_frame f;
  for (;;) {
    const ssize_t n = ::recv(fd_, &f, sizeof f, MSG_DONTWAIT);
    if (n == 0) peer_closed_ = true;
    if (n <= 0) break;  // drained (EAGAIN) or the peer closed
    if (n != sizeof f) continue;
    auto sync = wire::decode_sync(f);
    if (!sync) continue;  // board frames from elsewhere on the bus are not for us
    ++syncs;
    std::vector<BoardRecord> answers;
    {
      const std::lock_guard lock(mutex_);
      for (auto& b : boards_) {
        auto r = b->on_sync(sync.value().latch_seq);
        answers.insert(answers.end(), r.begin(), r.end());
      }
      answers = apply_bus_faults(answers);
    }
    send_all(answers);  // the whole bus's answers in one burst, as they follow on a real bus
  }
  return syncs;
}

void CounterBoardBus::send_all(const std::vector<BoardRecord>& records) {
  // One sendmmsg for the burst (one wake-up of the reader); each record stays its own datagram.
  std::vector<iovec> iov(records.size());
  std::vector<mmsghdr> msgs(records.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    iov[i] = {const_cast<can_frame*>(&records[i].frame),
              records[i].short_record ? 8 : sizeof(can_frame)};
    msgs[i] = {};
    msgs[i].msg_hdr.msg_iov = &iov[i];
    msgs[i].msg_hdr.msg_iovlen = 1;
  }
  std::size_t sent = 0;
  while (sent < msgs.size()) {
    const int n = ::sendmmsg(fd_, msgs.data() + sent, static_cast<unsigned>(msgs.size() - sent),
                             MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    pollfd p{fd_, POLLOUT, 0};
    if (n < 0 && errno != EAGAIN) return;
    if (::poll(&p, 1, 100) <= 0) return;  // peer not reading: drop, like a full tx queue
  }
}

void CounterBoardBus::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] {
    while (running_ && !peer_closed_) service(std::chrono::milliseconds(50));
  });
}

void CounterBoardBus::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

}  // namespace station::sim
