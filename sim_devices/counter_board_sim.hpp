// Simulated RLG counter boards on one simulated CAN bus (a socketpair/unix SEQPACKET fd).
#pragma once

#include <linux/can.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "sim_devices/counter_board_gyro.hpp"

namespace station::sim {

/// How an injected corruption damages a frame.
enum class CorruptKind : std::uint8_t {
  bad_dlc,       ///< right ID, DLC 3 (decode fails: bad DLC)
  garbage_id,    ///< unknown function code 0x700 + node, random bytes
  short_record,  ///< an 8-byte record on the socket instead of a 16-byte can_frame
};

/// One record a board puts on the bus: normally a can_frame, or a truncated 8-byte record.
struct BoardRecord {
  can_frame frame{};
  bool short_record = false;  ///< send only the first 8 bytes (injected transport corruption)
};

/// Damages `r` as `kind` says; garbage bytes come from `rng` (the node stays the frame's own).
void corrupt_record(BoardRecord& r, CorruptKind kind, std::mt19937_64& rng);

/// Probabilities, per frame on the bus, of the bus-level faults (each 0..1; all 0 = healthy).
struct BusFaultRates {
  double drop = 0;       ///< the frame is lost
  double duplicate = 0;  ///< the frame arrives twice
  double corrupt = 0;    ///< the frame is damaged (a CorruptKind drawn at random)
};

/// One simulated board: node id, its gyro and what it reports.
struct BoardConfig {
  std::uint8_t node = 1;                   ///< 1..16
  GyroConfig gyro;                         ///< the RLG on this board
  std::uint32_t initial_up = 0;            ///< up counter at time 0 (near 2^32 to force a wrap)
  std::uint32_t initial_down = 0;          ///< down counter at time 0
  std::uint32_t board_time_offset_us = 0;  ///< board clock at sim time 0, µs
  std::uint8_t temp_channels = 3;  ///< TEMPS: [0] sensor A, [1] sensor B, [2] air (0 = none)
  bool send_discharge = true;      ///< send DISCHARGE after TEMPS
  std::array<std::uint32_t, 2> discharge_ua{650, 650};  ///< nominal leg currents, µA
};

/// One counter board: latches on SYNC and builds its answer frames, with fault injection.
class CounterBoardSim {
 public:
  /// Builds the board at sim time 0 (no I/O).
  explicit CounterBoardSim(const BoardConfig& config);

  /// Advances the gyro to sim_time_s with chamber air at chamber_air_c.
  void step_to(double sim_time_s, double chamber_air_c) {
    gyro_.step_to(sim_time_s, chamber_air_c);
  }
  /// Latches on a SYNC: returns STATUS, COUNTS, TEMPS, DISCHARGE after injected faults.
  std::vector<BoardRecord> on_sync(std::uint8_t latch_seq);

  /// Up and down counters now (initial + dither + rotation, mod 2^32).
  std::uint32_t up_count() const;
  std::uint32_t down_count() const;
  /// The simulated gyro (true angle, temperatures, coefficients).
  const RlgGyroModel& gyro() const { return gyro_; }
  /// The true coefficients of this board's gyro.
  const TrueCoefficients& true_coefficients() const { return gyro_.config().coefficients; }
  std::uint8_t node() const { return config_.node; }

  /// Fault injection; each applies to the next frames this board sends. The setters are
  /// thread-safe (atomics): tests call them while the bus thread answers SYNCs.
  void drop_next_frames(int n) { drop_ = n; }
  void duplicate_next_frames(int n) { duplicate_ = n; }
  void corrupt_next_frames(int n, CorruptKind kind) {
    corrupt_kind_ = kind;  // kind first, so a frame counted by `n` never sees the old kind
    corrupt_ = n;
  }
  /// Temperature channel `channel` reads the sentinel 0x8000 and STATUS flags a sensor fault.
  void fail_temp_sensor(int channel, bool failed = true) { failed_temp_ = failed ? channel : -1; }
  /// Extra STATUS flags (kFlagLaserFault, kFlagDitherFault, ...) reported from now on.
  void set_extra_flags(std::uint8_t flags) { extra_flags_ = flags; }
  /// Stops (false) or resumes (true) answering SYNCs.
  void set_answering(bool answering) { answering_ = answering; }
  /// The gyro's power relay (RlgGyroModel::set_powered); the board has its own supply. While the
  /// gyro is off the board answers every SYNC as usual: STATUS with flags kFlagLaserFault |
  /// kFlagDitherFault (no discharge, no dither), COUNTS unchanged since the power went off,
  /// TEMPS (the sensors are the board's), DISCHARGE 0/0 uA. Not thread-safe: while a bus serves
  /// the board, call CounterBoardBus::set_powered.
  void set_powered(bool on) { gyro_.set_powered(on); }
  /// Board reset (a power cycle): up/down counters and the board clock restart from 0, and the
  /// first STATUS after it flags kFlagCounterReset. Not thread-safe: while a bus serves the
  /// board, call CounterBoardBus::reset_board instead.
  void reset();

 private:
  std::vector<can_frame> build_frames(std::uint8_t latch_seq);
  std::vector<BoardRecord> apply_faults(const std::vector<can_frame>& frames);

  BoardConfig config_;
  RlgGyroModel gyro_;
  std::mt19937_64 fault_rng_;
  // Counts and board time at the last reset(): what the counters read is counted from there.
  std::uint32_t clock_offset_us_ = 0;  ///< board clock at reset_at_s_, µs
  std::uint32_t up_at_reset_ = 0, down_at_reset_ = 0;
  double reset_at_s_ = 0;
  bool reset_pending_ = false;
  // Written by the test thread, read by the bus thread in on_sync().
  std::atomic<int> drop_{0}, duplicate_{0}, corrupt_{0}, failed_temp_{-1};
  std::atomic<CorruptKind> corrupt_kind_{CorruptKind::bad_dlc};
  std::atomic<std::uint8_t> extra_flags_{0};
  std::atomic<bool> answering_{true};
};

/// Several boards sharing one bus endpoint (one end of a SEQPACKET socketpair or a unix socket).
class CounterBoardBus {
 public:
  /// Takes ownership of fd (closed by the destructor); no I/O.
  explicit CounterBoardBus(int fd);
  ~CounterBoardBus();
  CounterBoardBus(const CounterBoardBus&) = delete;
  CounterBoardBus& operator=(const CounterBoardBus&) = delete;

  /// Adds a board; the reference stays valid for the bus's lifetime.
  CounterBoardSim& add_board(const BoardConfig& config);
  /// The board with this node id (throws std::out_of_range if none).
  CounterBoardSim& board(std::uint8_t node);
  /// Advances every board to sim_time_s with chamber air at chamber_air_c (thread-safe).
  void step_to(double sim_time_s, double chamber_air_c);
  /// Waits up to timeout for frames, answers every pending SYNC; returns SYNCs handled.
  int service(std::chrono::milliseconds timeout);
  /// Switches the power of the gyro on board `node` (CounterBoardSim::set_powered) under the bus
  /// lock; throws std::out_of_range if none.
  void set_powered(std::uint8_t node, bool on);
  /// The power-ups of the gyro on board `node` so far (a copy, under the bus lock).
  std::vector<PowerUp> power_ups(std::uint8_t node);
  /// Bus-level faults on the next `n` frames any board sends (thread-safe).
  void drop_frames(int n);
  void duplicate_frames(int n);
  void corrupt_frames(int n, CorruptKind kind);
  /// Bus-level fault probabilities from now on (thread-safe); `seed` makes them repeatable.
  void set_fault_rates(const BusFaultRates& rates, std::uint64_t seed);
  /// Ends every bus-level fault (counts and rates).
  void clear_faults();
  /// Resets the board with this node id (CounterBoardSim::reset) under the bus lock; throws
  /// std::out_of_range if none.
  void reset_board(std::uint8_t node);
  /// Background mode: a thread calls service() until stop() or the peer closes (~50 ms).
  void start();
  void stop();
  /// True once the peer closed its end (the background loop has then ended).
  bool peer_closed() const { return peer_closed_.load(); }

 private:
  void send_all(const std::vector<BoardRecord>& records);
  std::vector<BoardRecord> apply_bus_faults(const std::vector<BoardRecord>& records);

  int fd_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<CounterBoardSim>> boards_;
  // Bus-level faults, guarded by mutex_.
  int drop_ = 0, duplicate_ = 0, corrupt_ = 0;
  CorruptKind corrupt_kind_ = CorruptKind::bad_dlc;
  BusFaultRates rates_;
  std::mt19937_64 rng_{1};
  std::atomic<bool> running_{false};
  std::atomic<bool> peer_closed_{false};
  std::thread thread_;
};

}  // namespace station::sim
