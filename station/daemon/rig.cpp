// Rig construction from the configuration: register maps with overrides, transports, banks.
#include "station/daemon/rig.hpp"

#include <fmt/format.h>

#include "drivers/can/reconnecting_transport.hpp"
#include "drivers/chamber/chamber_map.hpp"
#include "drivers/chamber/modbus_chamber.hpp"
#include "drivers/counters/counter_frames.hpp"
#include "drivers/gpio/libgpiod_bank.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "drivers/turntable/modbus_turntable.hpp"
#include "drivers/turntable/turntable_map.hpp"

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
  auto chamber_map = dr::chamber_map::preset(c.chamber.preset, c.chamber.unit_id);
  dr::modbus::apply_overrides(chamber_map, c.chamber.overrides);
  const auto wire = [&o](const std::string& device, const dr::modbus::Endpoint& ep) {
    return o.modbus_wire_factory ? o.modbus_wire_factory(device, ep) : nullptr;
  };
  const auto chamber_ep = dr::modbus::parse_endpoint(c.chamber.endpoint);
  auto chamber = std::make_unique<dr::ModbusChamber>(
      "chamber", chamber_ep, chamber_map, c.chamber.timeout_s, wire("chamber", chamber_ep));
  chamber->set_readback_every(c.chamber.readback_every);
  chamber->set_tap(o.tap);
  chamber->client().set_clock(o.clock);
  rig.chamber = std::move(chamber);
  if (c.turntable) {
    auto map = dr::turntable_map::preset(c.turntable->preset, c.turntable->unit_id);
    dr::modbus::apply_overrides(map, c.turntable->overrides);
    const auto table_ep = dr::modbus::parse_endpoint(c.turntable->endpoint);
    auto table =
        std::make_unique<dr::ModbusTurntable>("turntable", table_ep, map, dr::TurntableLimits{},
                                              c.turntable->timeout_s, wire("turntable", table_ep));
    table->set_readback_every(c.turntable->readback_every);
    table->set_tap(o.tap);
    table->client().set_clock(o.clock);  // reconnect back-off on the run's clock too
    rig.turntable = std::move(table);
  }
  rig.counters = open_counters(c, o);
  if (c.gpio) {
    rig.gpio = o.gpio_factory ? o.gpio_factory(*c.gpio)
                              : std::make_unique<dr::gpio::LibgpiodBank>(*c.gpio);
    rig.gpio->set_tap(o.tap);
  }
  return rig;
}

}  // namespace station
