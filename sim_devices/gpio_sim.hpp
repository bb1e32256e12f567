// Simulated GPIO: chips with named pins (the hardware, outliving any request) and a GpioBank over
// them whose edges arrive on a real eventfd, so the station's production poll loop runs unchanged.
#pragma once

#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/common/unique_fd.hpp"
#include "drivers/gpio/gpio_bank.hpp"

namespace station::sim {

/// One simulated chip: its /dev name and line names by offset ("" = unnamed line).
struct GpioSimChipSpec {
  std::string name = "gpiochip0";
  std::vector<std::string> line_names;
};

/// Where a pin is: chip index and line offset.
struct GpioPinId {
  std::size_t chip = 0;
  unsigned offset = 0;
};

/// The simulated hardware: pins with electrical levels and request state. Thread-safe.
class GpioSimChips {
 public:
  /// Called under the chips' lock with the new electrical level and a CLOCK_MONOTONIC stamp.
  using EdgeSink = std::function<void(bool level_high, double mono_s)>;

  /// Builds the chips; every pin starts low and free. No I/O.
  explicit GpioSimChips(std::vector<GpioSimChipSpec> chips);

  /// Test API: drives an input pin ("DOOR_SW" or "gpiochip0:17") to an electrical level; a change
  /// on a requested input is an edge for its bank. Throws std::invalid_argument on unknown or
  /// output pins. Never blocks past the lock.
  void set_input(std::string_view line, bool level_high);
  /// Test API: electrical level of a pin; nullopt for an unknown line.
  std::optional<bool> pin_level(std::string_view line) const;
  /// Test API: consumer label holding the pin, "" when free; nullopt for an unknown line.
  std::optional<std::string> consumer(std::string_view line) const;
  /// Whether a bank has ever requested the pin as an output (a wired relay, say); false for an
  /// unknown line. A released output keeps its level, and this stays true.
  bool claimed_as_output(std::string_view line) const;

  /// Bank side: requests a pin as the kernel would (errors: no chip, no line, busy).
  drivers::Result<GpioPinId> request(const drivers::gpio::GpioLineConfig& cfg,
                                     const std::string& consumer, bool initial_high, EdgeSink sink);
  /// Bank side: drives a requested output pin.
  void drive(GpioPinId pin, bool level_high);
  /// Bank side: electrical level of a pin.
  bool level(GpioPinId pin) const;
  /// Bank side: frees the pin (keeps its level, as a released kernel line does).
  void release(GpioPinId pin);

 private:
  struct Pin {
    std::string name;
    bool high = false;
    bool output = false;
    bool ever_output = false;  // requested as an output at least once
    std::string consumer;      // "" = free
    EdgeSink sink;
  };
  struct Chip {
    std::string name;
    std::vector<Pin> pins;
  };
  Pin* lookup(std::string_view line);
  const Pin* lookup(std::string_view line) const;

  mutable std::mutex mu_;
  std::vector<Chip> chips_;
};

/// A GpioBank over simulated chips: same semantics as LibgpiodBank, events on an eventfd.
class GpioSimBank final : public drivers::gpio::GpioBank {
 public:
  /// Stores config and chips; no I/O. `device` names the bank in errors and tap records.
  GpioSimBank(drivers::gpio::GpioConfig config, std::shared_ptr<GpioSimChips> chips,
              std::string device = "gpio");
  ~GpioSimBank() override;
  GpioSimBank(const GpioSimBank&) = delete;
  GpioSimBank& operator=(const GpioSimBank&) = delete;

  drivers::Result<void> open() override;
  drivers::Result<bool> read(std::string_view role) override;
  drivers::Result<void> write(std::string_view role, bool active) override;
  drivers::Result<void> apply_safe_state() override;
  void close() override;
  int event_fd() const override { return efd_.get(); }
  drivers::Result<std::vector<drivers::gpio::GpioEdge>> read_events() override;
  void set_tap(drivers::Tap* tap) override { tap_ = tap; }
  const drivers::gpio::GpioConfig& config() const override { return config_; }

 private:
  struct Slot {
    const drivers::gpio::GpioLineConfig* cfg = nullptr;
    GpioPinId pin;
  };
  drivers::Result<void> request(const drivers::gpio::GpioLineConfig& cfg);
  drivers::Result<const Slot*> find_slot(std::string_view role) const;
  void on_edge(const drivers::gpio::GpioLineConfig& cfg, bool level_high, double mono_s);
  void drive(const Slot& slot, bool active);

  drivers::gpio::GpioConfig config_;
  std::shared_ptr<GpioSimChips> chips_;
  std::string device_;
  drivers::Tap* tap_ = nullptr;
  std::vector<Slot> slots_;
  drivers::UniqueFd efd_;
  std::mutex mu_;  // guards pending_ and the eventfd counter
  std::deque<drivers::gpio::GpioEdge> pending_;
};

}  // namespace station::sim
