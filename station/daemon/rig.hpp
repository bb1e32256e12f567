// The devices of one rig, built from the station configuration behind their interfaces (real
// or simulated hardware chosen by config, ros2_control's idea).
#pragma once

#include <functional>
#include <memory>

#include "drivers/can/can_transport.hpp"
#include "drivers/chamber/chamber.hpp"
#include "drivers/common/clock.hpp"
#include "drivers/common/tap.hpp"
#include "drivers/counters/counter_boards.hpp"
#include "drivers/gpio/gpio_bank.hpp"
#include "drivers/modbus/modbus_wire.hpp"
#include "drivers/registry/dialects.hpp"
#include "drivers/turntable/turntable.hpp"
#include "station/config/config.hpp"

namespace station {

/// Makes the GPIO bank for a config (default: libgpiod; --sim injects the simulated bank).
using GpioFactory =
    std::function<std::unique_ptr<drivers::gpio::GpioBank>(const drivers::gpio::GpioConfig&)>;

/// Makes the link under a Modbus / ASCII device's client (default: the real link).
using ModbusWireFactory = drivers::ModbusWireFactory;
using LineWireFactory = drivers::LineWireFactory;
/// Makes the counter boards' CAN transport (default: the configured one, reconnecting).
using CanTransportFactory = std::function<std::unique_ptr<drivers::can::CanTransport>()>;

/// How to build a rig.
struct RigOptions {
  drivers::Tap* tap = nullptr;  ///< every exchange of every device passes here when set
  GpioFactory gpio_factory;     ///< empty: LibgpiodBank
  /// Time of the links' reconnect back-off (nullptr: the steady clock; a simulation passes its
  /// clock so reconnects happen at the same simulated ticks every time). Not owned.
  const drivers::Clock* clock = nullptr;
  ModbusWireFactory modbus_wire_factory;      ///< empty: libmodbus (replay: the recording)
  LineWireFactory line_wire_factory;          ///< empty: sockets / termios (replay: recording)
  CanTransportFactory can_transport_factory;  ///< empty: the config's transport
  /// A replayed CAN log: a latch's answers end where the log's next SYNC begins, not at a
  /// wall-clock deadline.
  bool replayed_can = false;
};

/// The rig's devices. Turntable and GPIO are absent when the config has none.
struct Rig {
  std::unique_ptr<drivers::Chamber> chamber;
  std::unique_ptr<drivers::Turntable> turntable;
  std::unique_ptr<drivers::counters::CounterBoards> counters;
  std::unique_ptr<drivers::gpio::GpioBank> gpio;
};

/// Builds the drivers; no I/O. Every link (Modbus, CAN) opens on first use and reopens after a
/// loss with bounded back-off, so an unreachable device is found by probing it
/// (unreachable_devices in station/daemon/rig_probe.hpp), not here. Throws only on config errors.
Rig build_rig(const StationConfig& config, const RigOptions& options = {});

}  // namespace station
