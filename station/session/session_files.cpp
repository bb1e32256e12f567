// session.toml (toml++ writes it, so every string is quoted correctly) and result.json.
#include "station/session/session_files.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "station/common/input_error.hpp"
#include "station/store/fit_json.hpp"

namespace station {
namespace {

using nlohmann::json;

template <typename T>
json or_null(const std::optional<T>& v) {
  return v ? json(*v) : json(nullptr);
}

}  // namespace

std::string session_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::string gz = path + ".gz";
  const bool plain = fs::exists(path, ec), packed = fs::exists(gz, ec);
  if (plain && packed)
    throw InputError(
        fmt::format("{} and {} both exist: which one the run wrote cannot be told "
                    "(compressing a session replaces each file by its .gz); keep one",
                    path, gz));
  return packed ? gz : path;
}

bool session_file_exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::exists(path, ec) || std::filesystem::exists(path + ".gz", ec);
}

const std::vector<std::string>& sample_columns() {
  static const std::vector<std::string> columns{"serial", "net_pulses", "interval_s", "rate_dph",
                                                "temp_c", "temp2_c",    "air_c",      "setpoint_c",
                                                "flags",  "recording"};
  return columns;
}

json sample_row_json(const SampleRow& r) {
  return json::array({r.serial, or_null(r.net_pulses), or_null(r.interval_s), or_null(r.rate_dph),
                      or_null(r.temp_c), or_null(r.temp2_c), or_null(r.air_c),
                      or_null(r.setpoint_c), r.flags, r.recording});
}

std::optional<double> sample_number(const SampleRow& r, std::size_t column) {
  switch (column) {  // sample_columns() order, as sample_row_json writes them
    case 1:
      return r.net_pulses ? std::optional<double>(static_cast<double>(*r.net_pulses))
                          : std::nullopt;
    case 2:
      return r.interval_s;
    case 3:
      return r.rate_dph;
    case 4:
      return r.temp_c;
    case 5:
      return r.temp2_c;
    case 6:
      return r.air_c;
    case 7:
      return r.setpoint_c;
    case 8:
      return static_cast<double>(r.flags);
    default:
      return std::nullopt;  // serial (0), recording (9): not numbers
  }
}

TickCursor::TickCursor(Store& store, std::int64_t run_id) {
  for (const auto& slot : store.run_slots(run_id)) {
    readers_.emplace_back(store, run_id, slot.serial, false);
    SampleRow r;
    ahead_.push_back(readers_.back().next(r) ? std::optional(std::move(r)) : std::nullopt);
  }
  taken_.resize(readers_.size());
}

bool TickCursor::next(double& t_s, std::vector<const SampleRow*>& rows) {
  // A merge of the slots' series (each sorted by t_s); slot order within a tick.
  t_s = INFINITY;
  for (const auto& a : ahead_)
    if (a) t_s = std::min(t_s, a->t_s);
  if (!std::isfinite(t_s)) return false;
  rows.clear();
  for (std::size_t k = 0; k < ahead_.size(); ++k) {
    if (!ahead_[k] || ahead_[k]->t_s != t_s) continue;
    taken_[k] = std::move(*ahead_[k]);
    rows.push_back(&taken_[k]);
    SampleRow r;
    ahead_[k] = readers_[k].next(r) ? std::optional(std::move(r)) : std::nullopt;
  }
  return true;
}

void for_each_tick(Store& store, std::int64_t run_id,
                   const std::function<void(double, const std::vector<const SampleRow*>&)>& each) {
  TickCursor cursor(store, run_id);
  double t_s = 0;
  std::vector<const SampleRow*> rows;
  while (cursor.next(t_s, rows)) each(t_s, rows);
}

json tick_json(double t_s, const std::vector<const SampleRow*>& rows) {
  json tick = json::array({t_s});
  for (const auto* r : rows) tick.push_back(sample_row_json(*r));
  return tick;
}

namespace {

json bins_json(Store& store, std::int64_t run_id, const std::vector<RunSlot>& slots) {
  json out = json::array();
  for (const auto& slot : slots) {
    const auto d = store.model_data(slot.serial, {run_id});
    for (std::size_t i = 0; i < d.bias_dph.size(); ++i) {
      out.push_back({{"serial", slot.serial},
                     {"t_mid_s", d.t_mid_s[i]},
                     {"bias_dph", d.bias_dph[i]},
                     {"temp_c", d.temp_c[i]},
                     {"grad_c", d.grad_c[i]},
                     {"dtdt_c_per_h", d.dtdt_c_per_h[i]}});
    }
  }
  return out;
}

json events_json(Store& store, std::int64_t run_id) {
  json out = json::array();
  for (const auto& e : store.event_rows(run_id)) {
    out.push_back({{"t_s", e.t_s},
                   {"severity", e.severity},
                   {"source", e.source},
                   {"kind", e.kind},
                   {"message", e.message},
                   {"data", e.data_json ? json::parse(*e.data_json) : json(nullptr)}});
  }
  return out;
}

json fits_json(Store& store, std::int64_t run_id, const std::vector<RunSlot>& slots) {
  json out = json::array();
  for (const auto& slot : slots) {
    const auto f = store.latest_fit(slot.serial);
    if (!f || f->runs != std::vector<std::int64_t>{run_id}) continue;
    json j = fit_summary_json(f->fit, f->eval);
    j["serial"] = slot.serial;
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace

void write_session_header(const std::string& dir, const SessionHeader& h) {
  const auto path = std::filesystem::path(dir) / "session.toml";
  if (std::filesystem::exists(path)) return;
  toml::table t{{"format_version", kSessionFormatVersion},
                {"software_version", h.software_version},
                {"station", h.station},
                {"started_utc", h.started_utc},
                {"simulated", h.simulated},
                {"latitude_deg", h.latitude_deg},
                {"protocol_name", h.protocol_name}};
  if (h.sim_seed) t.insert("sim_seed", *h.sim_seed);
  toml::array slots;
  for (const auto& s : h.slots) {
    slots.push_back(toml::table{{"slot", s.slot},
                                {"node", s.node},
                                {"serial", s.serial},
                                {"axis", s.axis},
                                {"pulse_weight_arcsec", s.pulse_weight_arcsec},
                                {"earth_rate_dph", s.earth_rate_dph}});
  }
  t.insert("slot", std::move(slots));
  t.insert("resolved_json", h.resolved_json);
  t.insert("config", h.config_text);
  t.insert("protocol", h.protocol_text);
  std::ofstream out(path);
  out << "# A recorded station session (schemas/session.md).\n" << t << '\n';
  if (!out) throw InputError(fmt::format("{}: cannot write the session header", path.string()));
}

namespace {

// Cuts `path` after its last newline (a kill can stop a write mid-line) and counts its lines.
std::int64_t complete_lines(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return 0;
  std::int64_t lines = 0;
  std::uintmax_t size = 0, last_newline_end = 0;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    const auto n = static_cast<std::size_t>(in.gcount());
    for (std::size_t i = 0; i < n; ++i)
      if (buf[i] == '\n') {
        ++lines;
        last_newline_end = size + i + 1;
      }
    size += n;
  }
  in.close();
  if (last_newline_end != size) std::filesystem::resize_file(path, last_newline_end);
  return lines;
}

}  // namespace

void append_session_resume(const std::string& dir, double after_tick_s, double next_tick_s) {
  const std::filesystem::path d(dir);
  toml::table r{{"after_tick_s", after_tick_s},
                {"next_tick_s", next_tick_s},
                {"can_lines", complete_lines(d / "can.log")},
                {"modbus_lines", complete_lines(d / "modbus.log")},
                {"ascii_lines", complete_lines(d / "ascii.log")},
                {"gpio_lines", complete_lines(d / "gpio.log")}};
  std::ofstream out(d / "session.toml", std::ios::app);
  out << "\n[[resume]]  # a killed run resumed here (schemas/session.md)\n" << r << '\n';
  if (!out)
    throw InputError(fmt::format("{}: cannot append the resume", (d / "session.toml").string()));
}

std::vector<SessionResume> read_session_resumes(const std::string& path) {
  std::vector<SessionResume> out;
  const toml::table t = toml::parse_file(path);
  const auto* list = t["resume"].as_array();
  if (list == nullptr) return out;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const auto* r = list->get(i)->as_table();
    // after_tick_s = -1: the killed daemon had committed no tick (a batch lost whole).
    const auto number = [&](const char* key, double least = 0) {
      const auto v = r != nullptr ? (*r)[key].value<double>() : std::nullopt;
      if (!v || *v < least)
        throw InputError(
            fmt::format("{}: resume {}: key '{}': missing or below {}", path, i + 1, key, least));
      return *v;
    };
    const auto next = r != nullptr ? (*r)["next_tick_s"].value<double>() : std::nullopt;
    // ascii_lines: absent in sessions from before issue 20 (no line devices then).
    const auto* ascii_node = r != nullptr ? r->get("ascii_lines") : nullptr;
    const auto ascii = ascii_node != nullptr ? ascii_node->value<double>() : std::nullopt;
    if (ascii_node != nullptr && (!ascii || *ascii < 0))
      throw InputError(fmt::format("{}: resume {}: key 'ascii_lines': not a count", path, i + 1));
    out.push_back({number("after_tick_s", -1), next, static_cast<std::int64_t>(number("can_lines")),
                   static_cast<std::int64_t>(number("modbus_lines")),
                   static_cast<std::int64_t>(number("gpio_lines")),
                   static_cast<std::int64_t>(ascii.value_or(0))});
  }
  return out;
}

void append_session_end(const std::string& dir, const SessionEnd& end) {
  const auto path = std::filesystem::path(dir) / "session.toml";
  const toml::table t{{"state", end.state}, {"last_tick_s", end.last_tick_s}};
  std::ofstream out(path, std::ios::app);
  out << "\n[[end]]  # how the run ended (schemas/session.md)\n" << t << '\n';
  if (!out) throw InputError(fmt::format("{}: cannot append the end", path.string()));
}

SessionEnd read_session_end(const std::string& path) {
  const toml::table t = toml::parse_file(path);
  const auto* ends = t["end"].as_array();
  // The last one: a run that was ended, marked running again and resumed ended twice.
  const toml::table* e = ends != nullptr && !ends->empty() ? ends->back().as_table() : nullptr;
  const auto state = e != nullptr ? (*e)["state"].value<std::string>() : std::nullopt;
  const auto last = e != nullptr ? (*e)["last_tick_s"].value<double>() : std::nullopt;
  if (!state || !last || !std::isfinite(*last))
    throw InputError(
        fmt::format("{}: no [[end]] with 'state' and 'last_tick_s' (the run did not "
                    "end, or the file was cut)",
                    path));
  return {*state, *last};
}

json session_result_head_json(Store& store, std::int64_t run_id) {
  const auto run = store.find_run(run_id);
  const auto slots = store.run_slots(run_id);
  return {{"format_version", kSessionFormatVersion},
          {"run_id", run_id},
          {"state", run ? std::string(to_string(run->state)) : std::string()},
          {"sample_columns", sample_columns()},
          {"bins", bins_json(store, run_id, slots)},
          {"events", events_json(store, run_id)},
          {"fits", fits_json(store, run_id, slots)}};
}

json session_result_json(Store& store, std::int64_t run_id) {
  json out = session_result_head_json(store, run_id);
  json ticks = json::array();
  for_each_tick(store, run_id, [&ticks](double t_s, const std::vector<const SampleRow*>& rows) {
    ticks.push_back(tick_json(t_s, rows));
  });
  out["ticks"] = std::move(ticks);
  return out;
}

void write_session_result(Store& store, std::int64_t run_id, const std::string& dir) {
  const auto path = std::filesystem::path(dir) / "result.json";
  const auto tmp = std::filesystem::path(dir) / "result.json.tmp";
  {
    std::ofstream out(tmp);
    // The head (state, bins, events, fits) first, then one line per tick: greppable, diffable,
    // and read tick by tick by the replay.
    const json head = session_result_head_json(store, run_id);
    out << "{\n";
    for (const auto& [key, value] : head.items())
      out << fmt::format(" \"{}\": {},\n", key, value.dump(1));
    out << " \"ticks\": [";
    const char* sep = "\n  ";
    for_each_tick(store, run_id, [&](double t_s, const std::vector<const SampleRow*>& rows) {
      out << sep << tick_json(t_s, rows).dump();
      sep = ",\n  ";
    });
    out << "\n ]\n}\n";
    if (!out) throw InputError(fmt::format("{}: cannot write the session result", tmp.string()));
  }
  std::filesystem::rename(tmp, path);  // whole or not at all
}

}  // namespace station
