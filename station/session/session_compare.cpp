// Recorded result.json vs replayed: per quantity the largest difference, the first one found,
// missing and extra events (see session_replay.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <set>

#include "station/common/input_error.hpp"
#include "station/session/result_reader.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_log.hpp"
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
    if (a.is_array() && b.is_array() && a.size() == b.size()) {  // element by element
      for (std::size_t i = 0; i < a.size(); ++i) value(quantity, a[i], b[i], where);
      return;
    }
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

// "run 7 completed" and "run 1 completed" (or a fit's "runs 7") say the same: the replay's
// database numbers its run afresh.
// Likewise the database a message names ("f.db: serial ...") is the replay's own.
std::string without_run_ids(const std::string& message) {
  static const std::regex run_id(R"(\bruns? \d+(,\d+)*\b)");
  static const std::regex db_path(R"(\S+\.db\b)");
  return std::regex_replace(std::regex_replace(message, run_id, "run #"), db_path, "DB");
}

// The recorded ticks (read by result_reader while the daemon replayed) are compared in order with
// the replayed store's ticks, row by row, column by column. The largest difference per column is
// kept in an array (3.7 M values in a 13 h, 8-gyro session) and merged into the report at the end.
class TickComparer {
 public:
  TickComparer(Comparer& c, Store& store, std::int64_t run_id)
      : c_(c), cursor_(store, run_id), max_(sample_columns().size(), 0.0) {}

  void recorded(const json& tick) {
    ++recorded_;
    double t_s = 0;
    if (!cursor_.next(t_s, rows_)) return;
    ++replayed_;
    const json at = tick.is_array() && !tick.empty() ? tick[0] : json();
    if (!at.is_number() || at.get<double>() != t_s) {
      c_.differ(
          {{"at", {{"tick", at}}}, {"quantity", "tick t_s"}, {"recorded", at}, {"replayed", t_s}});
      return;
    }
    if (tick.size() - 1 != rows_.size())
      c_.differ({{"at", {{"tick", at}}},
                 {"quantity", "samples"},
                 {"recorded", tick.size() - 1},
                 {"replayed", rows_.size()}});
    for (std::size_t k = 0; k < std::min(tick.size() - 1, rows_.size()); ++k)
      row(tick[k + 1], *rows_[k], at);
  }
  /// Counts the replayed ticks left over, reports a count mismatch and the maxima; returns the
  /// number of replayed ticks.
  std::int64_t finish() {
    double t_s = 0;
    while (cursor_.next(t_s, rows_)) ++replayed_;
    if (recorded_ != replayed_)
      c_.differ({{"at", "ticks"}, {"recorded", recorded_}, {"replayed", replayed_}});
    const auto& columns = sample_columns();
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (seen_[i]) c_.r.max_abs_difference[columns[i]] = max_[i];
    return replayed_;
  }

 private:
  // One column: numbers within the tolerances (the largest difference kept), null against
  // null, serial and recording equal.
  bool same_cell(const json& a, const SampleRow& r, std::size_t i) {
    if (i == 0) return a.is_string() && a.get_ref<const std::string&>() == r.serial;
    if (i == 9) return a.is_boolean() && a.get<bool>() == r.recording;
    const auto y = sample_number(r, i);
    if (!y || !a.is_number()) return !y && a.is_null();
    const double x = a.get<double>(), d = std::abs(x - *y);
    max_[i] = std::max(max_[i], d);
    seen_[i] = true;
    return d <= c_.atol + c_.rtol * std::abs(x);
  }
  void row(const json& a, const SampleRow& r, const json& t_s) {
    const auto& columns = sample_columns();
    if (!a.is_array() || a.size() != columns.size()) {
      c_.differ({{"at", {{"tick", t_s}}},
                 {"quantity", "sample row"},
                 {"recorded", a},
                 {"replayed", sample_row_json(r)}});
      return;
    }
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (same_cell(a[i], r, i)) continue;
      c_.differ({{"at", {{"tick", t_s}, {"serial", a[0]}}},
                 {"quantity", columns[i]},
                 {"recorded", a[i]},
                 {"replayed", sample_row_json(r)[i]}});
    }
  }

  Comparer& c_;
  TickCursor cursor_;
  std::vector<const SampleRow*> rows_;
  std::vector<double> max_;
  std::vector<bool> seen_ = std::vector<bool>(sample_columns().size(), false);
  std::int64_t recorded_ = 0, replayed_ = 0;
};

void compare_list(Comparer& c, const char* what, const json& rec, const json& rep,
                  const char* prefix) {
  for (std::size_t i = 0; i < std::min(rec.size(), rep.size()); ++i)
    c.object(rec[i], rep[i], {{what, i}, {"serial", rec[i].value("serial", "")}}, prefix);
  if (rec.size() != rep.size())
    c.differ({{"at", what}, {"recorded", rec.size()}, {"replayed", rep.size()}});
}

// What of an event must be the same: everything, its message without the run's id and database.
json event_key(const json& e) {
  json k = e;
  if (k.is_object() && k.contains("message") && k["message"].is_string())
    k["message"] = without_run_ids(k["message"].get<std::string>());
  return k;
}

std::string event_text(const json& e) {
  const auto str = [&e](const char* key) {
    return e.contains(key) && e[key].is_string() ? e[key].get<std::string>() : std::string();
  };
  return fmt::format("t={} {} {} {}: {} {}", e.value("t_s", json()).dump(), str("severity"),
                     str("source"), str("kind"), without_run_ids(str("message")),
                     e.value("data", json()).dump());
}

// The events of the run's rig and protocol. The recording daemon's HTTP service (the address
// its live page listened at: source 'http') is no part of what a replay re-derives from the
// logs; its bytes are still proven by the digest over result.json.
json rig_events(const json& events) {
  json out = json::array();
  for (const auto& e : events)
    if (!(e.is_object() && e.value("source", "") == "http")) out.push_back(e);
  return out;
}

// The events as an ordered list: the i-th recorded event is the i-th replayed one, its data
// included. The notes name the events missing from or extra in the replay (with duplicates).
void compare_events(Comparer& c, const json& rec_all, const json& rep_all) {
  const json rec = rig_events(rec_all), rep = rig_events(rep_all);
  for (std::size_t i = 0; i < std::max(rec.size(), rep.size()); ++i) {
    const json a = i < rec.size() ? rec[i] : json(), b = i < rep.size() ? rep[i] : json();
    if (event_key(a) == event_key(b)) continue;
    c.differ({{"at", {{"event", i}}}, {"quantity", "event"}, {"recorded", a}, {"replayed", b}});
    c.r.notes.push_back(
        fmt::format("event {}: recorded {}", i, a.is_null() ? "none" : event_text(a)));
    c.r.notes.push_back(
        fmt::format("event {}: replayed {}", i, b.is_null() ? "none" : event_text(b)));
    break;
  }
  std::vector<std::string> missing, extra;
  for (const auto& e : rec) missing.push_back(event_text(e));
  for (const auto& e : rep) {
    const auto text = event_text(e);
    const auto at = std::find(missing.begin(), missing.end(), text);
    if (at != missing.end())
      missing.erase(at);
    else
      extra.push_back(text);
  }
  for (const auto& m : missing) c.r.notes.push_back("missing event: " + m);
  for (const auto& x : extra) c.r.notes.push_back("extra event: " + x);
}

// Every field of every fit; the warnings' texts without the run's id and database.
json fits_for_comparison(json fits) {
  for (auto& f : fits)
    if (f.is_object() && f.contains("warnings") && f["warnings"].is_array())
      for (auto& w : f["warnings"])
        if (w.is_string()) w = without_run_ids(w.get<std::string>());
  return fits;
}

/// The replayed object cut to the keys the recorded one has, recursively; each key cut is named in
/// `cut` ("prefix.key"). A session recorded by an older station lacks what later versions add
/// to a fit (issue 32: the walk line, the error model's prior): nothing recorded, nothing to
/// compare; the notes say what was not compared.
json recorded_keys_only(const json& rec, json rep, const std::string& prefix,
                        std::set<std::string>& cut) {
  if (!rec.is_object() || !rep.is_object()) return rep;
  for (auto it = rep.begin(); it != rep.end();) {
    if (!rec.contains(it.key())) {
      cut.insert(prefix + it.key());
      it = rep.erase(it);
      continue;
    }
    it.value() = recorded_keys_only(rec[it.key()], it.value(), prefix + it.key() + ".", cut);
    ++it;
  }
  return rep;
}

/// The replayed fits, each cut to what its recorded counterpart holds.
json replayed_fits_as_recorded(const json& rec_fits, json rep_fits, ReplayReport& r) {
  std::set<std::string> cut;
  for (std::size_t i = 0; i < rep_fits.size() && i < rec_fits.size(); ++i)
    rep_fits[i] = recorded_keys_only(rec_fits[i], rep_fits[i], "", cut);
  for (const auto& key : cut) r.notes.push_back("not in the recording, not compared: fit " + key);
  return rep_fits;
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

ReplayReport compare_with_store(const std::string& result_path, LogLineReader& result, Store& store,
                                std::int64_t run_id, double rtol, double atol) {
  ReplayReport r;
  Comparer c{rtol, atol, r};
  TickComparer ticks(c, store, run_id);
  // Each recorded tick compared as it is read, with the replayed store's, then forgotten.
  const json recorded = read_result_file(result, [&ticks](json&& tick) { ticks.recorded(tick); });
  r.ticks = ticks.finish();
  const auto version = recorded.value("format_version", json());
  if (version != kSessionFormatVersion)
    throw InputError(fmt::format("{}: format_version {} is not a version this station reads ({})",
                                 result_path, version.dump(), kSessionFormatVersion));
  const json replayed = session_result_head_json(store, run_id);
  r.bins = static_cast<std::int64_t>(replayed["bins"].size());
  r.events = static_cast<std::int64_t>(replayed["events"].size());
  r.fits = static_cast<std::int64_t>(replayed["fits"].size());
  // The header of the ticks: their columns' names and order are what gives each value its meaning.
  c.value("sample_columns", recorded.value("sample_columns", json()), replayed["sample_columns"],
          "run");
  c.value("state", recorded.value("state", json()), replayed["state"], "run");
  compare_list(c, "bin", recorded.value("bins", json::array()), replayed["bins"], "bin ");
  compare_events(c, recorded.value("events", json::array()), replayed["events"]);
  const json rec_fits = recorded.value("fits", json::array());
  compare_list(c, "fit", fits_for_comparison(rec_fits),
               fits_for_comparison(replayed_fits_as_recorded(rec_fits, replayed["fits"], r)),
               "fit ");
  return r;
}

}  // namespace station
