// The dialect table: one line per model.
#include "drivers/registry/dialects.hpp"

#include <fmt/format.h>

#include <algorithm>
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
#include "drivers/registry/rate_limit.hpp"
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

// The map of a Modbus dialect with the spec's float word order, then its point overrides, applied.
template <typename MapFn>
auto with_overrides(MapFn map) {
  return [map](const DeviceSpec& s) {
    auto m = map(s);
    if (s.word_order) modbus::set_float_word_order(m, *s.word_order);
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
  d->client().set_request_gap_s(s.request_gap_s);
  d->client().set_pipeline(s.modbus_pipeline);
  return d;
}
template <typename D>
std::unique_ptr<D> hooked_line(std::unique_ptr<D> d, const DeviceSpec& s, const LinkOptions& o) {
  d->set_tap(o.tap);
  d->set_clock(o.clock);
  d->set_readback_every(s.readback_every);
  return d;
}

// Link timing (docs/DEVICES.md, "Timing"). The makers' library waits longer for a reply than
// the station: [CCL] watlowf4.py:274-281 passes 10 s (F4), modbus.py:382 defaults to 3 s (F4T on
// RTU), especinteract.py:62 to 3 s (P300 serial), and over TCP it sets no bound at all
// (modbus.py:453, especinteract.py:118). A library call is made now and then; the station reads
// every device once a 1 Hz tick, one after the other (station/daemon/rig_reading.cpp), and a
// silent device costs the tick one timeout (a driver stops at its first failed read): 0.5 s keeps
// a dead chamber and a dead table within about one tick, while a live unit answers in tens of ms.
constexpr LinkTiming kStationTiming{0.5, 0.0};
// A Watlow on a serial line: 30 ms between requests, "using watlow recomended delay" ([CCL]
// modbus.py:373-375, slept after every request, :414); none over TCP (ModbusTCP.interact:475-492).
// The F4P manual gives no pause: Watlow's is kept for it too (an assumption, docs/DEVICES.md).
constexpr LinkTiming kWatlowTiming{0.5, 0.030};

}  // namespace

bool serial_unit(const DeviceSpec& s) {
  return s.gateway || std::holds_alternative<modbus::RtuEndpoint>(modbus_ep(s));
}

template <typename Device>
double default_request_gap_s(const Dialect<Device>& dialect, const DeviceSpec& spec) {
  if (dialect.transport != Transport::modbus || !serial_unit(spec)) return 0;
  return dialect.timing.serial_request_gap_s;
}

template double default_request_gap_s<Chamber>(const ChamberDialect&, const DeviceSpec&);
template double default_request_gap_s<Turntable>(const TurntableDialect&, const DeviceSpec&);

namespace {

const auto kF4Map = with_overrides([](const DeviceSpec& s) {
  return watlow_f4::map(s.unit_id, s.run_event, "watlow_f4", s.humidity_event);
});
const auto kF4tMap2Map = with_overrides(
    [](const DeviceSpec& s) { return watlow_f4::map2(s.unit_id, s.run_event, s.humidity_event); });
const auto kF4tMap = with_overrides([](const DeviceSpec& s) {
  return watlow_f4t::map(s.unit_id, s.run_event, serial_unit(s), 1, s.humidity_event,
                         s.product_input != 0 ? s.product_input : 2);
});

// What a Watlow driver takes from the spec besides its map.
WatlowInputs watlow_inputs(const DeviceSpec& s) {
  return {s.product_input, s.setpoint_low_c, s.setpoint_high_c};
}
const auto kF4pMap = with_overrides([](const DeviceSpec& s) { return watlow_f4p::map(s.unit_id); });
const auto kPlcChamberMap =
    with_overrides([](const DeviceSpec& s) { return chamber_map::generic_plc(s.unit_id); });
// The station's own table map: its driver's bound on a rate demand (docs/DEVICES.md).
constexpr double kPlcRateLimitDps = TurntableLimits{}.max_rate_dps;
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
     },
     0, kStationTiming},  // the station's own map: no maker's timing
    {"watlow_f4", Transport::modbus, "Watlow Series F4, Modbus RTU/TCP, int16 with decimals", "",
     true, kF4Map,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(
           std::make_unique<WatlowF4Chamber>(s.name, "watlow_f4", modbus_ep(s), kF4Map(s),
                                             s.timeout_s, modbus_wire(s, o), watlow_inputs(s)),
           s, o);
     },
     2, kWatlowTiming},
    {"watlow_f4t", Transport::modbus, "Watlow F4T, Modbus Data Map 1, float CDAB", "f4t", true,
     kF4tMap,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(
           std::make_unique<WatlowF4tChamber>(s.name, modbus_ep(s), kF4tMap(s), s.timeout_s,
                                              modbus_wire(s, o), watlow_inputs(s)),
           s, o);
     },
     4, kWatlowTiming},
    {"watlow_f4t_map2", Transport::modbus,
     "Watlow F4T in Data Map 2 (F4 compatibility): a limited set, input 2 is humidity", "", true,
     kF4tMap2Map,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(std::make_unique<WatlowF4Chamber>(s.name, "watlow_f4t_map2", modbus_ep(s),
                                                       kF4tMap2Map(s), s.timeout_s,
                                                       modbus_wire(s, o), watlow_inputs(s)),
                     s, o);
     },
     0, kWatlowTiming},
    {"watlow_f4p", Transport::modbus, "Watlow Series F4P, Modbus RTU, int16 with decimals", "",
     false, kF4pMap,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked(std::make_unique<WatlowF4pChamber>(s.name, modbus_ep(s), kF4pMap(s),
                                                        s.timeout_s, modbus_wire(s, o)),
                     s, o);
     },
     0, kWatlowTiming},
    {"espec_p300", Transport::ascii, "ESPEC P300 / SCP-220, ASCII over TCP 10001 or serial", "",
     false, nullptr,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Chamber> {
       return hooked_line(std::make_unique<EspecP300Chamber>(s.name, line_ep(s), s.unit_id,
                                                             s.timeout_s, line_wire(s, o)),
                          s, o);
     },
     // [CCL] EspecSerial.interact:88-110 sends the next command as soon as a reply ends.
     0, kStationTiming},
};

const std::vector<TurntableDialect> kTables{
    {"generic_plc",
     Transport::modbus,
     "the station's own Modbus map for a PLC-fronted table (docs/DEVICES.md)",
     "default",
     false,
     kPlcTableMap,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Turntable> {
       const double limit_dps = turntable_rate_limit(s)->dps;  // the dialect has its own
       return hooked(std::make_unique<ModbusTurntable>(s.name, modbus_ep(s), kPlcTableMap(s),
                                                       TurntableLimits{limit_dps}, s.timeout_s,
                                                       modbus_wire(s, o)),
                     s, o);
     },
     0,
     kStationTiming,
     {},
     kPlcRateLimitDps},  // the station's own map: no maker's timing
    {"acutrol3000", Transport::ascii, "Acutronic ACUTROL3000, ASCII over TCP 9878 or serial", "",
     false, nullptr,
     [](const DeviceSpec& s, const LinkOptions& o) -> std::unique_ptr<Turntable> {
       const auto framing = acutrol3000::framing_from_name(s.framing.empty() ? "auto" : s.framing);
       return hooked_line(std::make_unique<Acutrol3000Table>(s.name, line_ep(s), s.timeout_s,
                                                             line_wire(s, o), framing.value()),
                          s, o);
     },
     // [ACL] TM-8004 gives no response time; [py] acutrol3000.py:8 rests 0.2 s between GPIB
     // writes in a script, asked by no document.
     0, kStationTiming, acutrol3000::kFramingNames},
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

std::optional<TurntableRateLimit> turntable_rate_limit(const DeviceSpec& spec) {
  const auto own = turntable_dialect(spec.model).rate_limit_dps;
  if (own && (!spec.max_rate_dps || *own < *spec.max_rate_dps))
    return TurntableRateLimit{*own, true};
  if (spec.max_rate_dps) return TurntableRateLimit{*spec.max_rate_dps, false};
  return std::nullopt;
}

std::string chamber_models() {
  return names(chamber_dialects());
}
std::string turntable_models() {
  return names(turntable_dialects());
}

namespace {

// The link keys: the pause, the word order and a gateway are Modbus things; a gateway is a TCP
// endpoint in front of a serial line; nobody answers the broadcast address on a serial line
// (Modbus over Serial Line v1.02 §2.2); a word order needs float registers to order.
template <typename Device>
void validate_link(const Dialect<Device>& dialect, const DeviceSpec& spec) {
  if (dialect.transport != Transport::modbus) {
    for (const auto& [set, key] : {std::pair{spec.gateway, "gateway"},
                                   {spec.word_order.has_value(), "word_order"},
                                   {spec.request_gap_s > 0, "request_gap_s"},
                                   {spec.modbus_pipeline > 1, "modbus_pipeline"}})
      if (set)
        throw std::invalid_argument(
            fmt::format("{}: model '{}' speaks ASCII: {} applies to Modbus links only", key,
                        dialect.model, key));
    return;
  }
  const bool rtu = std::holds_alternative<modbus::RtuEndpoint>(modbus_ep(spec));
  if (spec.gateway && rtu)
    throw std::invalid_argument(
        "gateway: the endpoint is a serial line already (rtu:); gateway = true is for a tcp:// "
        "gateway in front of one");
  // Several requests outstanding is Modbus TCP's (Implementation Guide v1.0b §3.1.3, the
  // transaction id); a serial line, or a gateway in front of one, carries one at a time.
  if (spec.modbus_pipeline > 1 && serial_unit(spec))
    throw std::invalid_argument(fmt::format(
        "modbus_pipeline {}: {} carries one request at a time; pipelining is for a Modbus TCP "
        "unit that serves several transactions at once",
        spec.modbus_pipeline, rtu ? "a serial line" : "the serial line behind a gateway"));
  if (spec.modbus_pipeline > 1 && spec.request_gap_s > 0)
    throw std::invalid_argument(
        "modbus_pipeline: a request_gap_s between requests and several requests on the wire at "
        "once exclude each other");
  if (spec.unit_id == 0 && serial_unit(spec))
    throw std::invalid_argument(
        "unit_id 0 is the broadcast address of a serial line: no unit answers it (Modbus over "
        "Serial Line v1.02 2.2); give the unit's Modbus address, 1..247");
  auto map = dialect.map(spec);
  if (spec.word_order && modbus::set_float_word_order(map, *spec.word_order) == 0)
    throw std::invalid_argument(
        fmt::format("word_order: model '{}' has no float registers to order", dialect.model));
}

}  // namespace

template <typename Device>
void validate(const Dialect<Device>& dialect, const DeviceSpec& spec) {
  if (spec.run_event != 1 && !dialect.event_outputs) {
    std::string with;
    for (const auto& d : chamber_dialects())
      if (d.event_outputs) with += (with.empty() ? "" : ", ") + std::string(d.model);
    throw std::invalid_argument(fmt::format(
        "run_event: model '{}' has no event outputs (only {} do)", dialect.model, with));
  }
  if (spec.product_input != 0 &&
      (spec.product_input < 2 || spec.product_input > dialect.product_inputs))
    throw std::invalid_argument(
        dialect.product_inputs == 0
            ? fmt::format("product_input: model '{}' has no input to choose for the product "
                          "temperature ({})",
                          dialect.model, dialect.summary)
            : fmt::format("product_input {}: model '{}' takes 0 (none) or 2..{} (input 1 is the "
                          "air)",
                          spec.product_input, dialect.model, dialect.product_inputs));
  if (spec.humidity_event < 0 || spec.humidity_event > 8)
    throw std::invalid_argument(fmt::format("humidity_event {} not 0..8", spec.humidity_event));
  if (spec.setpoint_low_c && spec.setpoint_high_c &&
      !(*spec.setpoint_low_c < *spec.setpoint_high_c))
    throw std::invalid_argument("setpoint_low_c must be below setpoint_high_c");
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
    validate_link(dialect, spec);
    return;
  }
  if (!spec.overrides.empty())
    throw std::invalid_argument(fmt::format(
        "model '{}' speaks ASCII: it has no register points to override", dialect.model));
  (void)ascii::parse_line_endpoint(spec.endpoint);
  validate_link(dialect, spec);
}

template void validate<Chamber>(const ChamberDialect&, const DeviceSpec&);
template void validate<Turntable>(const TurntableDialect&, const DeviceSpec&);

}  // namespace station::drivers
