// Move-only RAII holders for libgpiod v1 handles: an open chip and one requested line.
#pragma once

#include <gpiod.h>

#include <memory>
#include <utility>

namespace station::drivers::gpio {

/// Deleter: closes the chip (libgpiod frees its line objects with it).
struct GpiodChipClose {
  void operator()(gpiod_chip* c) const noexcept { gpiod_chip_close(c); }
};

/// Owns one gpiod_chip*; move-only.
using ChipHandle = std::unique_ptr<gpiod_chip, GpiodChipClose>;

/// Owns the request on one gpiod_line*: on destruction an output is driven to its safe level,
/// then the line is released. The line object itself belongs to its chip, which must outlive it.
class RequestedLine {
 public:
  RequestedLine() = default;
  /// Takes over a requested line; safe_value is logical (the request carries the active-low flag).
  RequestedLine(gpiod_line* line, bool is_output, int safe_value)
      : line_(line), is_output_(is_output), safe_value_(safe_value) {}
  ~RequestedLine() { reset(); }
  RequestedLine(RequestedLine&& o) noexcept
      : line_(std::exchange(o.line_, nullptr)),
        is_output_(o.is_output_),
        safe_value_(o.safe_value_) {}
  RequestedLine& operator=(RequestedLine&& o) noexcept {
    if (this != &o) {
      reset();
      line_ = std::exchange(o.line_, nullptr);
      is_output_ = o.is_output_;
      safe_value_ = o.safe_value_;
    }
    return *this;
  }
  RequestedLine(const RequestedLine&) = delete;
  RequestedLine& operator=(const RequestedLine&) = delete;

  /// The requested line (still owned), nullptr if none.
  gpiod_line* get() const { return line_; }
  /// Drives an output to its safe level (best effort), then releases the request. No-op if empty.
  void reset() noexcept {
    if (line_ == nullptr) return;
    if (is_output_) gpiod_line_set_value(line_, safe_value_);
    gpiod_line_release(line_);
    line_ = nullptr;
  }

 private:
  gpiod_line* line_ = nullptr;
  bool is_output_ = false;
  int safe_value_ = 0;
};

}  // namespace station::drivers::gpio
