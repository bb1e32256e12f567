// Rig construction from the configuration: the dialect table builds chamber and table, then the
// counter boards' CAN transport and the GPIO bank.
#include "station/daemon/rig.hpp"

#include <fmt/format.h>

#include "drivers/can/reconnecting_transport.hpp"
#include "drivers/counters/counter_frames.hpp"
#include "drivers/gpio/libgpiod_bank.hpp"
#include "drivers/registry/dialects.hpp"

namespace station {

namespace dr = station::drivers;

namespace {

std::unique_ptr<dr::counters::CounterBoards> open_counters(const StationConfig& c,
                                                           const RigOptions& o) {
  dr::can::CanOpenOptions can_opts;
  can_opts.filters = dr::counters::board_frame_filters();
  can_opts.tap = o.tap;
  can_opts.tap_device = "can";
  can_opts.clock = o.clock;
  std::unique_ptr<dr::can::CanTransport> transport =
      o.can_transport_factory ? o.can_transport_factory()
                              : std::make_unique<dr::can::ReconnectingCanTransport>(
                                    dr::can::parse_can_spec(c.can_transport), can_opts);
  dr::counters::CounterBoardsConfig cc;
  cc.wall_clock_deadline = !o.replayed_can;
  cc.tick_timeout = std::chrono::milliseconds(c.can_tick_timeout_ms);
  for (const auto& s : c.slots) {
    cc.slots.push_back({static_cast<std::uint8_t>(s.node), s.serial, s.pulse_weight_arcsec});
  }
  return std::make_unique<dr::counters::CounterBoards>(std::move(transport), cc);
}

}  // namespace

Rig build_rig(const StationConfig& c, const RigOptions& o) {
  Rig rig;
  const dr::LinkOptions links{o.tap, o.clock, o.modbus_wire_factory, o.line_wire_factory};
  rig.chamber = dr::chamber_dialect(c.chamber.model).make(c.chamber, links);
  if (c.turntable)
    rig.turntable = dr::turntable_dialect(c.turntable->model).make(*c.turntable, links);
  rig.counters = open_counters(c, o);
  if (c.gpio) {
    rig.gpio = o.gpio_factory ? o.gpio_factory(*c.gpio)
                              : std::make_unique<dr::gpio::LibgpiodBank>(*c.gpio);
    rig.gpio->set_tap(o.tap);
  }
  return rig;
}

}  // namespace station
