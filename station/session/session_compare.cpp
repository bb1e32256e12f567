// Recorded result.json vs replayed: per quantity the largest difference, the first one found,
// missing and extra events (see session_replay.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>

#include "station/session/session_replay.hpp"

namespace station {
namespace {

using nlohmann::json;

struct Comparer {
  double rtol, atol;
  ReplayReport& r;

  void differ(json where) {
    r.same = false;
    if (r.first_difference.is_null()) r.first_difference = std::move(where);
  }
  // One value: numbers within the tolerances, everything else equal.
  void value(const std::string& quantity, const json& a, const json& b, const json& where) {
    if (a.is_object() && b.is_object()) return object(a, b, where, quantity + ".");
    if (a.is_number() && b.is_number()) {
      const double x = a.get<double>(), y = b.get<double>();
      const double d = std::abs(x - y);
      auto& m = r.max_abs_difference[quantity];
      m = std::max(m.is_number() ? m.get<double>() : 0.0, d);
      if (d > atol + rtol * std::abs(x))
        differ({{"at", where}, {"quantity", quantity}, {"recorded", a}, {"replayed", b}});
      return;
    }
    if (a != b) differ({{"at", where}, {"quantity", quantity}, {"recorded", a}, {"replayed", b}});
  }
  void object(const json& a, const json& b, const json& where, const std::string& prefix = "") {
    for (const auto& [key, va] : a.items()) value(prefix + key, va, b.value(key, json()), where);
    for (const auto& [key, vb] : b.items())
      if (!a.contains(key)) value(prefix + key, json(), vb, where);
  }
};

// "run 7 completed" and "run 1 completed" say the same: the replay's database numbers its run
// afresh.
// Likewise the database a message names ("f.db: serial ...") is the replay's own.
std::string without_run_ids(const std::string& message) {
  static const std::regex run_id(R"(\brun \d+\b)");
  static const std::regex db_path(R"(\S+\.db\b)");
  return std::regex_replace(std::regex_replace(message, run_id, "run #"), db_path, "DB");
}

void compare_ticks(Comparer& c, const json& rec, const json& rep) {
  const std::size_t n = std::min(rec.size(), rep.size());
  for (std::size_t i = 0; i < n; ++i) {
    const auto t_s = rec[i]["t_s"];
    c.value("tick t_s", t_s, rep[i]["t_s"], {{"tick", t_s}});
    const auto& a = rec[i]["samples"];
    const auto& b = rep[i]["samples"];
    if (a.size() != b.size())
      c.differ({{"at", {{"tick", t_s}}},
                {"quantity", "samples"},
                {"recorded", a.size()},
                {"replayed", b.size()}});
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k)
      c.object(a[k], b[k], {{"tick", t_s}, {"serial", a[k].value("serial", "")}});
  }
  if (rec.size() != rep.size())
    c.differ({{"at", "ticks"}, {"recorded", rec.size()}, {"replayed", rep.size()}});
}

void compare_list(Comparer& c, const char* what, const json& rec, const json& rep,
                  const char* prefix) {
  for (std::size_t i = 0; i < std::min(rec.size(), rep.size()); ++i)
    c.object(rec[i], rep[i], {{what, i}, {"serial", rec[i].value("serial", "")}}, prefix);
  if (rec.size() != rep.size())
    c.differ({{"at", what}, {"recorded", rec.size()}, {"replayed", rep.size()}});
}

void compare_events(Comparer& c, const json& rec, const json& rep) {
  const auto key = [](const json& e) {
    return fmt::format("t={} {} {} {}: {}", e["t_s"].dump(), e["severity"].get<std::string>(),
                       e["source"].get<std::string>(), e["kind"].get<std::string>(),
                       without_run_ids(e["message"].get<std::string>()));
  };
  std::vector<std::string> a, b;
  for (const auto& e : rec) a.push_back(key(e));
  for (const auto& e : rep) b.push_back(key(e));
  json missing = json::array(), extra = json::array();
  for (const auto& e : a)
    if (std::find(b.begin(), b.end(), e) == b.end()) missing.push_back(e);
  for (const auto& e : b)
    if (std::find(a.begin(), a.end(), e) == a.end()) extra.push_back(e);
  if (!missing.empty() || !extra.empty()) {
    c.differ({{"at", "events"}, {"missing", missing}, {"extra", extra}});
    for (const auto& m : missing) c.r.notes.push_back("missing event: " + m.get<std::string>());
    for (const auto& x : extra) c.r.notes.push_back("extra event: " + x.get<std::string>());
  }
}

}  // namespace

nlohmann::json ReplayReport::json() const {
  return {{"verdict", same ? "same" : "differs"},
          {"ticks", ticks},
          {"bins", bins},
          {"events", events},
          {"fits", fits},
          {"first_difference", first_difference},
          {"max_abs_difference",
           max_abs_difference.is_null() ? nlohmann::json::object() : max_abs_difference}};
}

ReplayReport compare_results(const nlohmann::json& recorded, const nlohmann::json& replayed,
                             double rtol, double atol) {
  ReplayReport r;
  r.ticks = static_cast<std::int64_t>(replayed.value("ticks", json::array()).size());
  r.bins = static_cast<std::int64_t>(replayed.value("bins", json::array()).size());
  r.events = static_cast<std::int64_t>(replayed.value("events", json::array()).size());
  r.fits = static_cast<std::int64_t>(replayed.value("fits", json::array()).size());
  Comparer c{rtol, atol, r};
  c.value("state", recorded["state"], replayed["state"], "run");
  compare_ticks(c, recorded["ticks"], replayed["ticks"]);
  compare_list(c, "bin", recorded["bins"], replayed["bins"], "bin ");
  compare_events(c, recorded["events"], replayed["events"]);
  json fits_a = recorded["fits"], fits_b = replayed["fits"];
  for (auto* f : {&fits_a, &fits_b})
    for (auto& x : *f) x.erase("warnings");  // texts; their numbers are compared as values
  compare_list(c, "fit", fits_a, fits_b, "fit ");
  return r;
}

}  // namespace station
