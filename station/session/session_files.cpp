// session.toml (toml++ writes it, so every string is quoted correctly) and result.json.
#include "station/session/session_files.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

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

json sample_json(const SampleRow& r) {
  return {{"serial", r.serial},
          {"net_pulses", or_null(r.net_pulses)},
          {"interval_s", or_null(r.interval_s)},
          {"rate_dph", or_null(r.rate_dph)},
          {"temp_c", or_null(r.temp_c)},
          {"temp2_c", or_null(r.temp2_c)},
          {"air_c", or_null(r.air_c)},
          {"setpoint_c", or_null(r.setpoint_c)},
          {"flags", r.flags},
          {"recording", r.recording}};
}

json ticks_json(Store& store, std::int64_t run_id, const std::vector<RunSlot>& slots) {
  std::map<double, json> by_tick;
  for (const auto& slot : slots) {
    for (const auto& r : store.samples(run_id, slot.serial, false)) {
      auto& t = by_tick[r.t_s];
      if (t.is_null()) t = {{"t_s", r.t_s}, {"samples", json::array()}};
      t["samples"].push_back(sample_json(r));
    }
  }
  json out = json::array();
  for (auto& [t_s, tick] : by_tick) out.push_back(std::move(tick));
  return out;
}

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

json session_result_json(Store& store, std::int64_t run_id) {
  const auto run = store.find_run(run_id);
  const auto slots = store.run_slots(run_id);
  return {{"format_version", kSessionFormatVersion},   {"run_id", run_id},
          {"state", run ? run->state : std::string()}, {"ticks", ticks_json(store, run_id, slots)},
          {"bins", bins_json(store, run_id, slots)},   {"events", events_json(store, run_id)},
          {"fits", fits_json(store, run_id, slots)}};
}

void write_session_result(Store& store, std::int64_t run_id, const std::string& dir) {
  const auto path = std::filesystem::path(dir) / "result.json";
  const auto tmp = std::filesystem::path(dir) / "result.json.tmp";
  {
    std::ofstream out(tmp);
    out << session_result_json(store, run_id).dump(1) << '\n';
    if (!out) throw InputError(fmt::format("{}: cannot write the session result", tmp.string()));
  }
  std::filesystem::rename(tmp, path);  // whole or not at all
}

}  // namespace station
