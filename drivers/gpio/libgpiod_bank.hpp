// The real GPIO bank over libgpiod 1.6 (v1 API): lines found by name or offset on named chips,
// input edges aggregated behind one epoll fd.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/common/unique_fd.hpp"
#include "drivers/gpio/gpio_bank.hpp"
#include "drivers/gpio/gpiod_handles.hpp"

namespace station::drivers::gpio {

/// GpioBank on /dev/gpiochipN character devices through libgpiod v1. Not thread-safe.
class LibgpiodBank final : public GpioBank {
 public:
  /// Stores the config; no I/O. `device` names the bank in errors and tap records.
  explicit LibgpiodBank(GpioConfig config, std::string device = "gpio");
  ~LibgpiodBank() override;
  LibgpiodBank(const LibgpiodBank&) = delete;
  LibgpiodBank& operator=(const LibgpiodBank&) = delete;

  Result<void> open() override;
  Result<bool> read(std::string_view role) override;
  Result<void> write(std::string_view role, bool active) override;
  Result<void> apply_safe_state() override;
  void close() override;
  int event_fd() const override { return epoll_.get(); }
  Result<std::vector<GpioEdge>> read_events() override;
  void set_tap(Tap* tap) override { tap_ = tap; }
  const GpioConfig& config() const override { return config_; }

 private:
  struct Slot {
    const GpioLineConfig* cfg = nullptr;
    RequestedLine line;
  };

  Result<gpiod_chip*> chip_for(const GpioLineConfig& cfg);
  Result<void> request(const GpioLineConfig& cfg);
  Result<void> watch(std::size_t slot_index);
  Result<void> drain(const Slot& slot, std::vector<GpioEdge>& out);
  Slot* find_slot(std::string_view role);
  Result<void> set_value(const Slot& slot, bool active);
  void tap(const TapRecord& record) noexcept;

  GpioConfig config_;
  std::string device_;
  Tap* tap_ = nullptr;
  // Declared before slots_ so the chips outlive the requested lines on destruction.
  std::map<std::string, ChipHandle> chips_;
  std::vector<Slot> slots_;
  UniqueFd epoll_;
};

}  // namespace station::drivers::gpio
