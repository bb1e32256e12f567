// Station configuration: TOML to StationConfig, strictly (unknown keys rejected).
#include "station/config/config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "compensation/limits.hpp"
#include "drivers/can/can_transport.hpp"
#include "drivers/modbus/endpoint.hpp"
#include "station/common/text_rule.hpp"
#include "station/config/toml_reader.hpp"

namespace station {
namespace {

namespace mb = drivers::modbus;

// Runs a parser that throws std::invalid_argument and re-throws it at `key`'s line.
template <typename F>
auto at_key(const TomlView& v, std::string_view key, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw v.error(key, e.what());
  }
}

mb::PointOverride read_override(const TomlView& v) {
  v.allow_only(
      {"name", "address", "type", "scale", "order", "function", "unit_id", "one_based", "access"});
  mb::PointOverride o;
  o.name = v.get_string("name");
  if (auto a = v.opt_integer("address")) {
    if (*a < 0 || *a > 65535) throw v.error("address", "must be 0..65535");
    o.address = static_cast<std::uint16_t>(*a);
  }
  if (auto s = v.opt_string("type"))
    o.type = at_key(v, "type", [&] { return mb::parse_point_type(*s); });
  if (auto s = v.opt_number("scale")) {
    if (*s == 0) throw v.error("scale", "must not be zero");
    o.scale = *s;
  }
  if (auto s = v.opt_string("order"))
    o.order = at_key(v, "order", [&] { return mb::parse_word_order(*s); });
  if (auto s = v.opt_string("function")) {
    o.function = at_key(v, "function", [&] { return mb::parse_function_code(*s); });
  }
  if (auto u = v.opt_integer_in("unit_id", 0, 247)) o.unit_id = static_cast<int>(*u);
  o.one_based = v.opt_bool("one_based");
  if (auto s = v.opt_string("access"))
    o.access = at_key(v, "access", [&] { return mb::parse_access(*s); });
  return o;
}

// The link keys of a device: unit id, float word order, a gateway in front, the timing given
// (what is not given is the dialect's: link_defaults).
void read_link(const TomlView& v, DeviceConfig& d) {
  d.unit_id = static_cast<int>(v.opt_integer_in("unit_id", 0, 247).value_or(1));
  if (auto t = v.opt_number("timeout_s")) {
    if (!(*t > 0 && *t <= 10)) throw v.error("timeout_s", "must be in (0, 10] s");
    d.timeout_s = *t;
  }
  d.request_gap_s = v.opt_number_in("request_gap_s", 0.0, 1.0, "s").value_or(0.0);
  d.modbus_pipeline = static_cast<int>(v.opt_integer_in("modbus_pipeline", 1, 8).value_or(1));
  d.gateway = v.opt_bool("gateway").value_or(false);
  if (auto w = v.opt_string("word_order"))
    d.word_order = at_key(v, "word_order", [&] { return mb::parse_float_word_order(*w); });
}

// The dialect's timing where the file gives none (drivers/registry/dialects.cpp, "Timing").
template <typename Dialect>
void link_defaults(const TomlView& v, const Dialect& dialect, DeviceConfig& d) {
  if (!v.table().contains("timeout_s")) d.timeout_s = dialect.timing.timeout_s;
  if (!v.table().contains("request_gap_s"))
    d.request_gap_s = drivers::default_request_gap_s(dialect, d);
}

// [chamber] / [turntable]: the model picks the dialect (drivers/registry), which says what
// endpoint and keys it takes; everything is checked here, before anything moves.
DeviceConfig read_device(const TomlView& v, bool is_chamber) {
  v.allow_only({"endpoint",       "model",           "preset",
                "unit_id",        "timeout_s",       "readback_every",
                "point",          "run_event",       "product_input",
                "humidity_event", "setpoint_low_c",  "setpoint_high_c",
                "request_gap_s",  "modbus_pipeline", "word_order",
                "gateway",        "framing",         "on_foreign_setpoint",
                "max_rate_dps",   "max_accel_dps2"});
  if (!is_chamber && v.table().contains("on_foreign_setpoint"))
    throw v.error("on_foreign_setpoint", "is a [chamber] key");
  for (const char* key : {"max_rate_dps", "max_accel_dps2"})
    if (is_chamber && v.table().contains(key)) throw v.error(key, "is a [turntable] key");
  DeviceConfig d;
  d.name = is_chamber ? "chamber" : "turntable";
  if (v.opt_string("model") && v.opt_string("preset"))
    throw v.error("preset", "give `model` only (`preset` is its old name)");
  const char* model_key = v.opt_string("preset") ? "preset" : "model";
  d.model = v.opt_string(model_key).value_or("generic_plc");
  d.endpoint = v.get_string("endpoint");
  read_link(v, d);
  d.readback_every =
      static_cast<int>(v.opt_integer_in("readback_every", 1, 600).value_or(d.readback_every));
  d.run_event = static_cast<int>(v.opt_integer_in("run_event", 1, 8).value_or(1));
  d.product_input = static_cast<int>(v.opt_integer_in("product_input", 0, 4).value_or(0));
  d.humidity_event = static_cast<int>(v.opt_integer_in("humidity_event", 0, 8).value_or(2));
  d.setpoint_low_c = v.opt_number("setpoint_low_c");
  d.setpoint_high_c = v.opt_number("setpoint_high_c");
  d.framing = v.opt_string("framing").value_or("");
  // The table's limits as its maker rates it (or the unit is set): the start checks a protocol's
  // rate ladders against them (daemon/acceptance_runner.hpp, check_acceptance_rig).
  d.max_rate_dps = v.opt_number_in("max_rate_dps", 1e-3, 1e5, "deg/s");
  d.max_accel_dps2 = v.opt_number_in("max_accel_dps2", 1e-3, 1e6, "deg/s^2");
  for (const auto& p : v.table_array("point")) d.overrides.push_back(read_override(p));
  const auto check = [&](const auto* dialect) {
    d.model = std::string(dialect->model);
    at_key(v, "endpoint", [&] {
      if (dialect->transport == drivers::Transport::modbus)
        (void)mb::parse_endpoint(d.endpoint);
      else
        (void)drivers::ascii::parse_line_endpoint(d.endpoint);
      return 0;
    });
    // The dialect checks its keys and the point overrides; the message names the key given.
    try {
      drivers::validate(*dialect, d);
    } catch (const std::invalid_argument& e) {
      const std::string_view what = e.what();
      for (const char* key :
           {"product_input", "humidity_event", "setpoint_low_c", "run_event", "unit_id", "gateway",
            "word_order", "request_gap_s", "framing", "modbus_pipeline"})
        if (what.rfind(key, 0) == 0 && v.table().contains(key)) throw v.error(key, what);
      throw v.error(d.run_event != 1 ? "run_event" : "point", what);
    }
    link_defaults(v, *dialect, d);
  };
  if (is_chamber)
    check(at_key(v, model_key, [&] { return &drivers::chamber_dialect(d.model); }));
  else
    check(at_key(v, model_key, [&] { return &drivers::turntable_dialect(d.model); }));
  return d;
}

/// The text rule (common/text_rule.hpp) at `key`: "FILE:LINE: key 'K': U+XXXX at ...".
void require_identifier_at(const TomlView& v, std::string_view key, const std::string& text) {
  if (const auto problem = identifier_problem(text)) throw v.error(key, *problem);
}

SlotConfig read_slot(const TomlView& v) {
  v.allow_only({"node", "serial", "pulse_weight_arcsec", "axis", "relay", "part"});
  SlotConfig s;
  const long long node = v.get_integer("node");
  if (node < 1 || node > 16) throw v.error("node", "CAN node must be 1..16");
  s.node = static_cast<int>(node);
  if (auto serial = v.opt_string("serial")) {  // a default: a run may give its own
    if (serial->empty()) throw v.error("serial", "must not be empty");
    require_identifier_at(v, "serial", *serial);
    s.serial = *serial;
  }
  s.pulse_weight_arcsec = v.opt_number("pulse_weight_arcsec").value_or(1.5);
  if (!(s.pulse_weight_arcsec > 0 && s.pulse_weight_arcsec < 100)) {
    throw v.error("pulse_weight_arcsec", "must be in (0, 100) arcsec");
  }
  s.axis = v.opt_string("axis").value_or("up");
  s.enu = at_key(v, "axis", [&] { return compensation::parse_axis(s.axis); });
  s.relay = v.opt_string("relay").value_or("");
  if (auto part = v.opt_string("part")) {
    if (part->empty()) throw v.error("part", "must not be empty");
    require_identifier_at(v, "part", *part);
    s.part = *part;
    s.part_line = v.line_of("part");
  }
  return s;
}

LimitsConfig read_limits(const TomlView& v) {
  v.allow_only({"min_setpoint_c", "max_setpoint_c", "max_ramp_c_per_min", "air_margin_c"});
  LimitsConfig l;
  // Physical temperatures (compensation/limits.hpp); no chamber ramps faster than 100 C/min.
  const double lo = compensation::kMinTempC, hi = compensation::kMaxTempC;
  l.min_setpoint_c = v.opt_number_in("min_setpoint_c", lo, hi, "C").value_or(l.min_setpoint_c);
  l.max_setpoint_c = v.opt_number_in("max_setpoint_c", lo, hi, "C").value_or(l.max_setpoint_c);
  l.max_ramp_c_per_min =
      v.opt_number_in("max_ramp_c_per_min", 0.0, 100.0, "C/min").value_or(l.max_ramp_c_per_min);
  // How far the air may overshoot the setpoint limits before it is a fault (a controller's
  // overshoot on a step is a few degrees; 0 makes any overshoot a safe hold).
  l.air_margin_c = v.opt_number_in("air_margin_c", 0.0, 50.0, "C").value_or(l.air_margin_c);
  if (!(l.min_setpoint_c < l.max_setpoint_c)) {
    throw v.error("max_setpoint_c", "must be above min_setpoint_c");
  }
  if (!(l.max_ramp_c_per_min > 0)) throw v.error("max_ramp_c_per_min", "must be positive");
  return l;
}

// The [gpio] table plus every slot's `relay`, as the driver's line map: the TOML keys are the
// roles (tower_green is role "tower.green"); slot N's relay is role "relay.N".
drivers::gpio::GpioConfig read_gpio(const TomlView& root, const std::optional<TomlView>& v,
                                    const std::vector<SlotConfig>& slots) {
  std::map<std::string, std::string> roles;
  std::string chip = "gpiochip0";
  if (v) {
    v->allow_only({"chip", "interlock", "estop", "tower_green", "tower_amber", "tower_red"});
    chip = v->opt_string("chip").value_or(chip);
    for (std::string role : {"interlock", "estop", "tower_green", "tower_amber", "tower_red"}) {
      if (auto line = v->opt_string(role)) {
        if (role.starts_with("tower_")) role = "tower." + role.substr(6);
        roles[role] = *line;
      }
    }
  }
  for (std::size_t i = 0; i < slots.size(); ++i) {
    if (!slots[i].relay.empty())
      roles[drivers::gpio::roles::relay(static_cast<int>(i + 1))] = slots[i].relay;
  }
  const TomlView& where = v ? *v : root;
  return at_key(where, v ? "chip" : "slot",
                [&] { return drivers::gpio::make_gpio_config(roles, chip); });
}

void check_slots_unique(const TomlView& root, const std::vector<SlotConfig>& slots) {
  std::set<int> nodes;
  std::set<std::string> serials;
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const auto key = fmt::format("slot[{}]", i);
    if (!nodes.insert(slots[i].node).second) throw root.error("slot", key + ": node used twice");
    if (!slots[i].serial.empty() && !serials.insert(slots[i].serial).second)
      throw root.error("slot", key + ": serial used twice");
  }
}

/// [station]: name, latitude, T_ref, bin length, the lost-tick share, the part file.
void read_station_table(const TomlView& root, const std::string& path, StationConfig& c) {
  auto st = root.opt_table("station");
  if (!st) throw root.error("station", "missing [station] table (latitude_deg is required)");
  st->allow_only({"name", "latitude_deg", "ref_temp_c", "bin_s", "max_lost_share", "parts"});
  c.name = st->opt_string("name").value_or(c.name);
  require_identifier_at(*st, "name", c.name);
  c.latitude_deg = st->get_number("latitude_deg");
  if (c.latitude_deg < -90 || c.latitude_deg > 90)
    throw st->error("latitude_deg", "must be -90..90");
  c.ref_temp_c =
      st->opt_number_in("ref_temp_c", compensation::kMinTempC, compensation::kMaxTempC, "C")
          .value_or(c.ref_temp_c);
  // A bin of more than a day would average over a whole thermal cycle.
  c.bin_s = st->opt_number_in("bin_s", 1.0, 86400.0, "s").value_or(c.bin_s);
  c.max_lost_share = st->opt_number("max_lost_share").value_or(c.max_lost_share);
  if (!(c.max_lost_share >= 0 && c.max_lost_share <= 1))
    throw st->error("max_lost_share", "must be 0..1 (a share of the record window's ticks)");
  if (auto parts = st->opt_string("parts")) {
    if (parts->empty()) throw st->error("parts", "must not be empty");
    // Relative to the configuration file, so a station's files travel together.
    c.parts_path = (std::filesystem::path(path).parent_path() / *parts).string();
  }
}

/// [http]: where the service listens, its token file and its protocol folder (relative paths
/// are beside the configuration file).
void read_http_table(const TomlView& h, const std::string& path, HttpConfig& http) {
  h.allow_only({"listen", "token_file", "protocol_dir"});
  const auto beside = [&path](const std::string& p) {
    return (std::filesystem::path(path).parent_path() / p).string();
  };
  http.listen = h.opt_string("listen").value_or(http.listen);
  if (http.listen.empty()) throw h.error("listen", "must not be empty (HOST:PORT)");
  if (auto t = h.opt_string("token_file")) {
    if (t->empty()) throw h.error("token_file", "must not be empty");
    http.token_file = beside(*t);
  }
  if (auto d = h.opt_string("protocol_dir")) {
    if (d->empty()) throw h.error("protocol_dir", "must not be empty");
    http.protocol_dir = beside(*d);
  }
}

/// [can]: the transport and the tick's deadline for the boards' answers.
void read_can_table(const TomlView& root, StationConfig& c) {
  auto can = root.opt_table("can");
  if (!can) throw root.error("can", "missing [can] table");
  can->allow_only({"transport", "tick_timeout_ms"});
  c.can_transport = can->get_string("transport");
  at_key(*can, "transport", [&] { return drivers::can::parse_can_spec(c.can_transport); });
  const long long tick_ms = can->opt_integer("tick_timeout_ms").value_or(200);
  if (tick_ms < 10 || tick_ms > 900) {
    throw can->error("tick_timeout_ms", "must be 10..900 ms (it must fit in the 1 s tick)");
  }
  c.can_tick_timeout_ms = static_cast<int>(tick_ms);
}

}  // namespace

StationConfig parse_station_config(const std::string& text, const std::string& path) {
  const toml::table tbl = TomlView::parse_text(text, path);
  const TomlView root(tbl, path);
  root.allow_only(
      {"station", "limits", "chamber", "turntable", "can", "gpio", "slot", "http", "fleet"});
  StationConfig c;
  c.path = path;
  c.text = text;
  read_station_table(root, path, c);
  if (auto l = root.opt_table("limits")) c.limits = read_limits(*l);
  if (auto h = root.opt_table("http")) read_http_table(*h, path, c.http);
  if (auto f = root.opt_table("fleet")) {
    // Central rows name the station that recorded them: every station of a line needs its own.
    if (!root.opt_table("station")->opt_string("name"))
      throw f->error("pg", "[fleet] needs [station] name, a name unique in the fleet");
    c.fleet = read_fleet_config(*f, path);
  }
  auto chamber = root.opt_table("chamber");
  if (!chamber) throw root.error("chamber", "missing [chamber] table");
  c.chamber = read_device(*chamber, true);
  c.on_foreign_setpoint = chamber->opt_string("on_foreign_setpoint").value_or("restore");
  if (c.on_foreign_setpoint != "restore" && c.on_foreign_setpoint != "hold")
    throw chamber->error("on_foreign_setpoint", "must be \"restore\" or \"hold\"");
  if (auto t = root.opt_table("turntable")) c.turntable = read_device(*t, false);
  read_can_table(root, c);
  for (const auto& s : root.table_array("slot")) c.slots.push_back(read_slot(s));
  if (c.slots.empty()) throw root.error("slot", "no [[slot]] entries: the rig has no gyros");
  check_slots_unique(root, c.slots);
  const auto gpio = root.opt_table("gpio");
  const bool relays = std::any_of(c.slots.begin(), c.slots.end(),
                                  [](const SlotConfig& s) { return !s.relay.empty(); });
  if (gpio || relays) c.gpio = read_gpio(root, gpio, c.slots);
  return c;
}

StationConfig load_station_config(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_station_config(ss.str(), path);
}

}  // namespace station
