// Probing a rig (`station probe`, and the check before a run starts): reads each configured
// device once (chamber, turntable, one counter-board SYNC, GPIO inputs) and reports what it got;
// a device that fails is one typed error line.
#include "station/daemon/rig_probe.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "drivers/counters/counter_frames.hpp"
#include "station/daemon/rig_reading.hpp"

namespace station {
namespace {

namespace dr = station::drivers;
namespace dc = station::drivers::counters;
using nlohmann::json;

/// What one device (or one counter-board slot) gave.
struct DeviceReport {
  std::string device;              ///< "chamber", "turntable", "can", "slot 1", "gpio"
  std::string where;               ///< endpoint, transport or chip
  std::optional<dr::Error> error;  ///< set when the device failed
  std::string summary;             ///< the values read, one line of text
  json fields = json::object();    ///< the same values for --json
};

DeviceReport failed(std::string device, std::string where, dr::Error e) {
  return {std::move(device), std::move(where), std::move(e), {}, json::object()};
}

const char* yes_no(bool b) {
  return b ? "yes" : "no";
}

std::string alarm_text(const dr::AlarmBits& a) {
  if (!a.any()) return "none";
  std::string s;
  auto add = [&s](bool on, const char* name) {
    if (on) s += (s.empty() ? "" : ",") + std::string(name);
  };
  add(a.deviation, "deviation");
  add(a.sensor_break, "sensor_break");
  add(a.door_open, "door_open");
  add(a.high_limit_trip, "high_limit_trip");
  add(a.other, "controller_alarm");
  return s;
}

// A failure names the dialect the station spoke ("model watlow_f4p: ...").
dr::Error with_model(const std::string& model, dr::Error e) {
  e.message = "model " + model + ": " + e.message;
  return e;
}

json finite_or_null(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

// The link as configured: the unit id asked, the reply timeout, the pause between requests
// (docs/DEVICES.md, "what to check on the real unit first").
std::string link_text(const dr::DeviceSpec& d) {
  return fmt::format("link: unit {}{}, timeout {:.2f} s, request gap {:.3f} s", d.unit_id,
                     d.gateway ? " behind a gateway" : "", d.timeout_s, d.request_gap_s);
}
json link_json(const dr::DeviceSpec& d) {
  return {{"unit_id", d.unit_id},
          {"gateway", d.gateway},
          {"timeout_s", d.timeout_s},
          {"request_gap_s", d.request_gap_s}};
}

// What the controller says it is (dialect, identity, units, decimals, limits) before its values:
// a unit the dialect cannot read correctly fails here with the dialect's one line.
DeviceReport chamber_report(const dr::Result<dr::ChamberIdentity>& id, const RigReading& in,
                            const StationConfig& c) {
  const std::string& where = c.chamber.endpoint;
  if (!id) return failed("chamber", where, with_model(c.chamber.model, id.error()));
  if (!in.chamber) return failed("chamber", where, *in.chamber_error);
  const dr::ChamberState& s = *in.chamber;
  const dr::ChamberIdentity& i = id.value();
  DeviceReport d{"chamber", where, {}, {}, json::object()};
  d.summary = fmt::format(
      "air {:.1f} C, product {:.1f} C, setpoint {:.1f} C, ramp {:.2f} C/min, mode {}, "
      "alarms {}, run {}; model {}: {}, units {}{}, setpoint limits {:.1f}..{:.1f} C; {}; {}",
      s.air_c, s.product_c, s.setpoint_c, s.ramp_c_per_min, dr::to_string(s.mode),
      alarm_text(s.alarms), s.run_enabled ? "on" : "off", c.chamber.model, i.identity, i.units,
      i.decimals >= 0 ? fmt::format(", {} decimals", i.decimals) : "", i.setpoint_low_c,
      i.setpoint_high_c, i.notes, link_text(c.chamber));
  // NaN (sensor break, no product sensor) is not JSON: it becomes null.
  d.fields = {{"model", c.chamber.model},
              {"identity", i.identity},
              {"units", i.units},
              {"decimals", i.decimals >= 0 ? json(i.decimals) : json(nullptr)},
              {"setpoint_limits_c", {i.setpoint_low_c, i.setpoint_high_c}},
              {"notes", i.notes},
              {"link", link_json(c.chamber)},
              {"air_c", finite_or_null(s.air_c)},
              {"product_c", finite_or_null(s.product_c)},
              {"setpoint_c", s.setpoint_c},
              {"ramp_c_per_min", s.ramp_c_per_min},
              {"mode", dr::to_string(s.mode)},
              {"alarms", alarm_text(s.alarms)},
              {"run_enabled", s.run_enabled}};
  return d;
}

DeviceReport table_report(const dr::Result<std::string>& id, const RigReading& in,
                          const StationConfig& c) {
  const std::string& where = c.turntable->endpoint;
  if (!id) return failed("turntable", where, with_model(c.turntable->model, id.error()));
  if (!in.table) return failed("turntable", where, *in.table_error);
  const dr::TurntableState& s = *in.table;
  DeviceReport d{"turntable", where, {}, {}, json::object()};
  d.summary = fmt::format(
      "mode {}, angle {:.4f} deg, rate {:.4f} deg/s, in_position {}, at_rate {}, fault {}, "
      "interlock_open {}; model {}{}",
      dr::to_string(s.mode), s.angle_deg, s.rate_dps, yes_no(s.in_position), yes_no(s.at_rate),
      yes_no(s.fault), yes_no(s.interlock_open), c.turntable->model,
      id.value().empty() ? "" : ": " + id.value());
  d.fields = {{"model", c.turntable->model},
              {"identity", id.value()},
              {"mode", dr::to_string(s.mode)},
              {"angle_deg", s.angle_deg},
              {"rate_dps", s.rate_dps},
              {"in_position", s.in_position},
              {"at_rate", s.at_rate},
              {"fault", s.fault},
              {"interlock_open", s.interlock_open}};
  return d;
}

std::string flag_text(std::uint8_t f) {
  if (f == 0) return "none";
  std::string s;
  auto add = [&s, f](std::uint8_t bit, const char* name) {
    if (f & bit) s += (s.empty() ? "" : ",") + std::string(name);
  };
  add(dc::kFlagLaserFault, "laser_fault");
  add(dc::kFlagTempSensorFault, "temp_sensor_fault");
  add(dc::kFlagCounterReset, "counter_reset");
  add(dc::kFlagDitherFault, "dither_fault");
  return s;
}

DeviceReport slot_report(std::size_t index, const dc::CounterReading& r, std::uint8_t seq,
                         const StationConfig& c) {
  const std::string device = fmt::format("slot {}", index + 1);
  const std::string where = fmt::format("node {} {}", r.node, r.serial);
  if (!r.answered) {
    return failed(device, where,
                  {dr::ErrorKind::timeout, fmt::format("node {}: no complete answer to latch {} "
                                                       "within {} ms",
                                                       r.node, seq, c.can_tick_timeout_ms)});
  }
  std::string temps = r.temps_missing ? "missing" : "";
  for (double t : r.temps_c) temps += fmt::format("{}{:.2f}", temps.empty() ? "" : " ", t);
  const std::string discharge =
      r.discharge_ua ? fmt::format("{}/{} uA", (*r.discharge_ua)[0], (*r.discharge_ua)[1])
                     : (r.discharge_missing ? "missing" : "n/a");
  const std::string counts =
      r.has_delta ? fmt::format("{} net pulses", r.net_pulses) : "n/a (first latch)";
  DeviceReport d{device, where, {}, {}, json::object()};
  d.summary = fmt::format(
      "answered, counts delta {}, temps [{}] C, flags 0x{:02x} ({}), "
      "discharge {}",
      counts, temps, r.status_flags, flag_text(r.status_flags), discharge);
  d.fields = {{"node", r.node},
              {"serial", r.serial},
              {"answered", true},
              {"net_pulses", r.has_delta ? json(r.net_pulses) : json(nullptr)},
              {"temps_c", r.temps_c},
              {"status_flags", r.status_flags},
              {"flags", flag_text(r.status_flags)},
              {"discharge_ua", r.discharge_ua ? json(*r.discharge_ua) : json(nullptr)}};
  return d;
}

std::vector<DeviceReport> counter_reports(const RigReading& in, const StationConfig& c) {
  if (!in.counters) return {failed("can", c.can_transport, *in.counters_error)};
  const dc::TickResult& t = *in.counters;
  std::vector<DeviceReport> out;
  DeviceReport bus{"can", c.can_transport, {}, {}, json::object()};
  std::size_t answered = 0;
  for (const auto& r : t.readings) answered += r.answered ? 1 : 0;
  bus.summary = fmt::format("latch {}: {}/{} boards answered, {} corrupt, {} unknown frames{}",
                            t.latch_seq, answered, t.readings.size(), t.corrupt_frames,
                            t.unknown_frames, t.last_error.empty() ? "" : "; " + t.last_error);
  bus.fields = {{"latch_seq", t.latch_seq},
                {"answered", answered},
                {"corrupt_frames", t.corrupt_frames},
                {"unknown_frames", t.unknown_frames}};
  out.push_back(std::move(bus));
  for (std::size_t i = 0; i < t.readings.size(); ++i)
    out.push_back(slot_report(i, t.readings[i], t.latch_seq, c));
  return out;
}

/// Each input line of the bank as the reading found it (the bank's order).
std::vector<DeviceReport> gpio_reports(const dr::gpio::GpioConfig& bank, const RigReading& in) {
  std::vector<DeviceReport> out;
  for (const auto& line : bank.lines) {
    if (line.direction != dr::gpio::GpioDirection::input) continue;
    const std::string device = "gpio " + line.role;
    const auto error = std::find_if(in.gpio_errors.begin(), in.gpio_errors.end(),
                                    [&line](const auto& e) { return e.first == line.role; });
    const std::optional<bool> value = line.role == dr::gpio::roles::interlock ? in.door_closed
                                      : line.role == dr::gpio::roles::estop   ? in.estop_pressed
                                                                              : std::nullopt;
    if (error != in.gpio_errors.end() || !value) {
      out.push_back(failed(device, line.where(),
                           error != in.gpio_errors.end()
                               ? error->second
                               : dr::Error{dr::ErrorKind::io, "not an input the station reads"}));
      continue;
    }
    DeviceReport d{device, line.where(), {}, {}, json::object()};
    d.summary = *value ? "active" : "inactive";
    d.fields = {{"active", *value}};
    out.push_back(std::move(d));
  }
  return out;
}

void print_text(std::ostream& out, const StationConfig& c, const std::vector<DeviceReport>& rs) {
  out << fmt::format("probe of '{}' ({})\n", c.name, c.path);
  std::size_t bad = 0;
  for (const auto& r : rs) {
    if (r.error) {
      ++bad;
      out << fmt::format("{:<16} {:<28} error {}: {}\n", r.device, r.where,
                         dr::to_string(r.error->kind), r.error->message);
    } else {
      out << fmt::format("{:<16} {:<28} ok: {}\n", r.device, r.where, r.summary);
    }
  }
  out << (bad == 0 ? std::string("all devices answered\n")
                   : fmt::format("{} of {} failed\n", bad, rs.size()));
}

void print_json(std::ostream& out, const StationConfig& c, const std::vector<DeviceReport>& rs) {
  json devices = json::array();
  bool ok = true;
  for (const auto& r : rs) {
    json d = {{"device", r.device}, {"where", r.where}, {"ok", !r.error}};
    if (r.error) {
      ok = false;
      d["error"] = {{"kind", dr::to_string(r.error->kind)}, {"message", r.error->message}};
    } else {
      d["values"] = r.fields;
    }
    devices.push_back(std::move(d));
  }
  out << json{{"station", c.name}, {"config", c.path}, {"ok", ok}, {"devices", devices}}.dump(2)
      << '\n';
}

/// What the devices say they are, then one reading of the rig (read_rig, the daemon's own),
/// with one SYNC of the counter boards; a device that did not say what it is is not read again
/// (one timeout per dead device). Opening the GPIO bank drives outputs to their safe levels (as
/// the daemon does); it is closed again after.
std::vector<DeviceReport> probe_all(const StationConfig& config, Rig& rig) {
  constexpr std::uint8_t kSeq = 1;
  const auto chamber_id = rig.chamber->identify();
  const auto table_id = rig.turntable ? rig.turntable->identify() : dr::Result<std::string>("");
  std::optional<dr::Error> gpio_open;
  if (rig.gpio)
    if (auto ok = rig.gpio->open(); !ok) gpio_open = ok.error();
  const RigReading in = read_rig(rig, RigReadPlan{kSeq, chamber_id.ok(), table_id.ok(), false});
  rig.counters->forget_latches();  // the probe's latch is no baseline for a run
  std::vector<DeviceReport> reports{chamber_report(chamber_id, in, config)};
  if (rig.turntable) reports.push_back(table_report(table_id, in, config));
  for (auto& r : counter_reports(in, config)) reports.push_back(std::move(r));
  if (!rig.gpio) return reports;
  const auto& bank = rig.gpio->config();
  if (gpio_open) {
    reports.push_back(failed("gpio", bank.lines.empty() ? "gpio" : bank.lines[0].chip, *gpio_open));
  } else {
    for (auto& r : gpio_reports(bank, in)) reports.push_back(std::move(r));
    rig.gpio->close();
  }
  return reports;
}

}  // namespace

int probe_rig(const StationConfig& config, const RigOptions& options, std::ostream& out,
              bool json_out) {
  Rig rig = build_rig(config, options);
  const std::vector<DeviceReport> reports = probe_all(config, rig);
  if (json_out) {
    print_json(out, config, reports);
  } else {
    print_text(out, config, reports);
  }
  for (const auto& r : reports)
    if (r.error) return 1;
  return 0;
}

std::vector<std::string> unreachable_devices(const StationConfig& config, Rig& rig) {
  std::vector<std::string> out;
  for (const auto& r : probe_all(config, rig)) {
    if (r.error)
      out.push_back(fmt::format("{}: {} {} unreachable: {}", config.path, r.device, r.where,
                                r.error->message));
  }
  return out;
}

}  // namespace station
