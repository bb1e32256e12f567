// The dialect table: one line per model.
#include "drivers/registry/dialects.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <variant>

#include "drivers/chamber/espec_p300/espec_p300_chamber.hpp"
#include "drivers/chamber/generic_plc/generic_plc_map.hpp"
#include "drivers/chamber/generic_plc/modbus_chamber.hpp"
#include "drivers/chamber/watlow_f4/f4_map.hpp"
#include "drivers/chamber/watlow_f4/watlow_f4_chamber.hpp"
#include "drivers/chamber/watlow_f4p/f4p_map.hpp"
#include "drivers/chamber/watlow_f4p/watlow_f4p_chamber.hpp"
#include "drivers/chamber/watlow_f4t/f4t_map.hpp"
#include "drivers/chamber/watlow_f4t/watlow_f4t_chamber.hpp"
#include "drivers/turntable/acutrol3000/acutrol3000_table.hpp"
#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"
#include "drivers/turntable/generic_plc/generic_plc_map.hpp"
#include "drivers/turntable/generic_plc/modbus_turntable.hpp"

namespace station::drivers {
namespace {

modbus::Endpoint modbus_ep(const DeviceSpec& s) {
  return modbus::parse_endpoint(s.endpoint);
}
ascii::LineEndpoint line_ep(const DeviceSpec& s) {
  return ascii::parse_line_endpoint(s.endpoint);
}

// The map of a Modbus dialect with the spec's overrides applied.
template <typename MapFn>
auto with_overrides(MapFn map) {
  return [map](const DeviceSpec& s) {
    auto m = map(s);
    modbus::apply_overrides(m, s.overrides);
    return m;
  };
}

std::unique_ptr<modbus::ModbusWire> modbus_wire(const DeviceSpec& s, const LinkOptions& o) {
  return o.modbus_wire ? o.modbus_wire(s.name, modbus_ep(s)) : nullptr;
}
std::unique_ptr<ascii::LineWire> line_wire(const DeviceSpec& s, const LinkOptions& o) {
  return o.line_wire ? o.line_wire(s.name, line_ep(s)) : nullptr;
}

// Wires a Modbus driver's client to the options and the spec's read-back schedule.
template <typename D>
std::unique_ptr<D> hooked(std::unique_ptr<D> d, const DeviceSpec& s, const LinkOptions& o) {
  d->set_tap(o.tap);
  d->set_readback_every(s.readback_every);
  d->client().set_clock(o.clock);
  return d;
}
template <typename D>
std::unique_ptr<D> hooked_line(std::unique_ptr<D> d, const DeviceSpec& s, const LinkOptions& o) {
  d->set_tap(o.tap);
  d->set_clock(o.clock);
  d->set_readback_every(s.readback_every);
  return d;
}

bool rtu(const DeviceSpec& s) {
  return std::holds_alternative<modbus::RtuEndpoint>(modbus_ep(s));
}

const auto kF4Map = with_overrides(
    [](const DeviceSpec& s) { return watlow_f4::map(s.unit_id, s.run_event, "watlow_f4"); });
const auto kF4tMap2Map = with_overrides(
    [](const DeviceSpec& s) { return watlow_f4::map(s.unit_id, s.run_event, "watlow_f4t_map2"); });
const auto kF4tMap = with_overrides(
    [](const DeviceSpec& s) { return watlow_f4t::map(s.unit_id, s.run_event, rtu(s)); });
const auto kF4pMap = with_overrides([](const DeviceSpec& s) { return watlow_f4p::map(s.unit_id); });
const auto kPlcChamberMap =
    with_overrides([](const DeviceSpec& s) { return chamber_map::generic_plc(s.unit_id); });
const auto kPlcTableMap =
    with_overrides([](const DeviceSpec& s) { return turntable_map::generic_plc(s.unit_id); });

const std::vector<ChamberDialect> kChambers{
    {"generic_plc", Transport::modbus,
     "the station's own Modbus map for a PLC-run chamber (docs/DEVICES.md)", "default", false,
     kPlcChamberMap,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(std::make_unique<ModbusChamber>(s.name, modbus_ep(s), kPlcChamberMap(s),
                                                     s.timeout_s, modbus_wire(s, o)),
                     s, o);
     }},
    {"watlow_f4", Transport::modbus, "Watlow Series F4, Modbus RTU/TCP, int16 with decimals", "",
     true, kF4Map,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(std::make_unique<WatlowF4Chamber>(s.name, "watlow_f4", modbus_ep(s), kF4Map(s),
                                                       s.timeout_s, modbus_wire(s, o)),
                     s, o);
     }},
    {"watlow_f4t", Transport::modbus, "Watlow F4T, Modbus Data Map 1, float CDAB", "f4t", true,
     kF4tMap,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(std::make_unique<WatlowF4tChamber>(s.name, modbus_ep(s), kF4tMap(s),
                                                        s.timeout_s, modbus_wire(s, o)),
                     s, o);
     }},
    {"watlow_f4t_map2", Transport::modbus, "Watlow F4T in F4-compatibility map (the F4 registers)",
     "", true, kF4tMap2Map,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(
           std::make_unique<WatlowF4Chamber>(s.name, "watlow_f4t_map2", modbus_ep(s),
                                             kF4tMap2Map(s), s.timeout_s, modbus_wire(s, o)),
           s, o);
     }},
    {"watlow_f4p", Transport::modbus, "Watlow Series F4P, Modbus RTU, int16 with decimals", "",
     false, kF4pMap,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(std::make_unique<WatlowF4pChamber>(s.name, modbus_ep(s), kF4pMap(s),
                                                        s.timeout_s, modbus_wire(s, o)),
                     s, o);
     }},
    {"espec_p300", Transport::ascii, "ESPEC P300 / SCP-220, ASCII over TCP 10001 or serial", "",
     false, nullptr,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked_line(std::make_unique<EspecP300Chamber>(s.name, line_ep(s), s.unit_id,
                                                             s.timeout_s, line_wire(s, o)),
                          s, o);
     }},
};

const std::vector<TurntableDialect> kTables{
    {"generic_plc", Transport::modbus,
     "the station's own Modbus map for a PLC-fronted table (docs/DEVICES.md)", "default", false,
     kPlcTableMap,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Turntable> {
       return hooked(
           std::make_unique<ModbusTurntable>(s.name, modbus_ep(s), kPlcTableMap(s),
                                             TurntableLimits{}, s.timeout_s, modbus_wire(s, o)),
           s, o);
     }},
    {"acutrol3000", Transport::ascii, "Acutronic ACUTROL3000, ASCII over TCP 9878 or serial", "",
     false, nullptr,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Turntable> {
       const auto framing = acutrol3000::framing_from_name(s.framing.empty() ? "auto" : s.framing);
       return hooked_line(std::make_unique<Acutrol3000Table>(s.name, line_ep(s), s.timeout_s,
                                                             line_wire(s, o), framing.value()),
                          s, o);
     },
     acutrol3000::kFramingNames},
};

// Whether `model` is one of the row's comma-separated aliases.
bool is_alias(std::string_view aliases, std::string_view model) {
  while (!aliases.empty()) {
    const auto comma = aliases.find(',');
    if (aliases.substr(0, comma) == model) return true;
    aliases = comma == std::string_view::npos ? "" : aliases.substr(comma + 1);
  }
  return false;
}

template <typename D>
std::string names(std::span<const Dialect<D>> all) {
  std::string out;
  for (const auto& d : all) out += (out.empty() ? "" : ", ") + std::string(d.model);
  return out;
}

template <typename D>
const Dialect<D>& find(std::span<const Dialect<D>> all, std::string_view model, const char* what) {
  for (const auto& d : all)
    if (d.model == model || is_alias(d.aliases, model)) return d;
  throw std::invalid_argument(
      fmt::format("unknown {} model '{}' (known: {})", what, model, names(all)));
}

}  // namespace

std::span<const ChamberDialect> chamber_dialects() {
  return kChambers;
}
std::span<const TurntableDialect> turntable_dialects() {
  return kTables;
}
const ChamberDialect& chamber_dialect(std::string_view model) {
  return find(chamber_dialects(), model, "chamber");
}
const TurntableDialect& turntable_dialect(std::string_view model) {
  return find(turntable_dialects(), model, "turntable");
}
std::string chamber_models() {
  return names(chamber_dialects());
}
std::string turntable_models() {
  return names(turntable_dialects());
}

template <typename Device>
void validate(const Dialect<Device>& dialect, const DeviceSpec& spec) {
  if (spec.run_event != 1 && !dialect.event_outputs) {
    std::string with;
    for (const auto& d : chamber_dialects())
      if (d.event_outputs) with += (with.empty() ? "" : ", ") + std::string(d.model);
    throw std::invalid_argument(fmt::format(
        "run_event: model '{}' has no event outputs (only {} do)", dialect.model, with));
  }
  if (!spec.framing.empty() && !is_alias(dialect.framings, spec.framing))
    throw std::invalid_argument(
        dialect.framings.empty()
            ? fmt::format("framing: model '{}' has no reply framing to choose", dialect.model)
            : fmt::format("framing '{}': model '{}' takes one of {}", spec.framing, dialect.model,
                          dialect.framings));
  if (dialect.transport == Transport::modbus) {
    (void)modbus::parse_endpoint(spec.endpoint);
    if (spec.run_event < 1 || spec.run_event > 8)
      throw std::invalid_argument(fmt::format("run_event {} not 1..8", spec.run_event));
    (void)dialect.map(spec);  // applies the overrides: throws naming a bad one
    return;
  }
  if (!spec.overrides.empty())
    throw std::invalid_argument(fmt::format(
        "model '{}' speaks ASCII: it has no register points to override", dialect.model));
  (void)ascii::parse_line_endpoint(spec.endpoint);
}

template void validate<Chamber>(const ChamberDialect&, const DeviceSpec&);
template void validate<Turntable>(const TurntableDialect&, const DeviceSpec&);

}  // namespace station::drivers
