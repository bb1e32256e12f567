// Protocol files: strict TOML parsing into steps; shipped protocols embedded by name.
#include "station/config/protocol.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "compensation/limits.hpp"
#include "station/builtin_protocols.hpp"
#include "station/config/acceptance_steps.hpp"
#include "station/common/text_rule.hpp"
#include "station/config/toml_reader.hpp"

namespace station {
namespace {

struct KindName {
  StepKind kind;
  const char* name;
};
constexpr KindName kKinds[] = {{StepKind::set_temperature, "set_temperature"},
                               {StepKind::soak, "soak"},
                               {StepKind::hold, "hold"},
                               {StepKind::record_start, "record_start"},
                               {StepKind::record_stop, "record_stop"},
                               {StepKind::lock_turntable, "lock_turntable"},
                               {StepKind::rate_ladder, "rate_ladder"},
                               {StepKind::positions, "positions"},
                               {StepKind::power_cycles, "power_cycles"}};

StepKind kind_of(const TomlView& v) {
  const std::string type = v.get_string("type");
  for (const auto& k : kKinds) {
    if (type == k.name) return k.kind;
  }
  throw v.error("type", fmt::format("unknown step type '{}' (set_temperature, soak, hold, "
                                    "record_start, record_stop, lock_turntable, rate_ladder, "
                                    "positions, power_cycles)",
                                    type));
}

// Bounds of step values. A step longer than a week is a typo (the paper's whole protocol takes
// 12.8 h), and without a bound a hold of 1e300 s would never end. Temperatures are physical
// (absolute zero to 1000 C, compensation/limits.hpp; the station's [limits] clamp them further
// at run time); ramps and tolerances wider than any chamber's.
constexpr double kMaxStepS = 7 * 86400.0;
constexpr double kMaxRampCPerH = 6000.0;  // 100 C/min
constexpr double kMaxToleranceC = 100.0;
constexpr double kMaxPositionDeg = 360.0;

double number_in(const TomlView& v, const char* key, double fallback, double hi, const char* unit) {
  return v.opt_number_in(key, 0.0, hi, unit).value_or(fallback);
}

void read_set_temperature(const TomlView& v, Step& s) {
  v.allow_only({"type", "label", "setpoint_c", "to_start", "ramp_c_per_h", "wait", "tolerance_c",
                "timeout_s"});
  s.setpoint_c =
      v.opt_number_in("setpoint_c", compensation::kMinTempC, compensation::kMaxTempC, "C");
  s.to_start = v.opt_bool("to_start").value_or(false);
  if (s.setpoint_c.has_value() == s.to_start) {
    throw v.error("setpoint_c", "give exactly one of setpoint_c or to_start = true");
  }
  s.ramp_c_per_h = number_in(v, "ramp_c_per_h", 0.0, kMaxRampCPerH, "C/h");
  s.ramp_line = static_cast<int>(v.line_of("ramp_c_per_h"));
  s.wait = v.opt_bool("wait").value_or(true);
  s.tolerance_c = number_in(v, "tolerance_c", 1.0, kMaxToleranceC, "C");
}

Step read_step(const TomlView& v) {
  Step s;
  s.kind = kind_of(v);
  s.line = static_cast<int>(v.table().source().begin.line);
  s.label = v.opt_string("label").value_or(to_string(s.kind));
  if (const auto problem = note_problem(s.label, kMaxLabelBytes)) throw v.error("label", *problem);
  switch (s.kind) {
    case StepKind::set_temperature:
      read_set_temperature(v, s);
      break;
    case StepKind::soak:
      v.allow_only({"type", "label", "tolerance_c", "duration_s", "timeout_s"});
      s.tolerance_c = number_in(v, "tolerance_c", 0.5, kMaxToleranceC, "C");
      s.duration_s = number_in(v, "duration_s", 1800.0, kMaxStepS, "s");
      break;
    case StepKind::hold:
      v.allow_only({"type", "label", "duration_s"});
      s.duration_s = v.get_number("duration_s");
      if (!(s.duration_s > 0)) throw v.error("duration_s", "must be positive");
      if (s.duration_s > kMaxStepS) {
        throw v.error("duration_s", fmt::format("{:g} s is longer than {:g} s (7 days)",
                                                s.duration_s, kMaxStepS));
      }
      break;
    case StepKind::lock_turntable:
      v.allow_only({"type", "label", "position_deg"});
      s.position_deg =
          v.opt_number_in("position_deg", -kMaxPositionDeg, kMaxPositionDeg, "deg").value_or(0.0);
      break;
    case StepKind::record_start:
    case StepKind::record_stop:
      v.allow_only({"type", "label"});
      break;
    case StepKind::rate_ladder:
    case StepKind::positions:
    case StepKind::power_cycles:
      read_acceptance_step(v, s);
      break;
  }
  s.timeout_s = number_in(v, "timeout_s", 0.0, kMaxStepS, "s");
  return s;
}

}  // namespace

const char* to_string(StepKind k) {
  for (const auto& kn : kKinds) {
    if (kn.kind == k) return kn.name;
  }
  return "unknown";
}

Protocol parse_protocol(const std::string& text, const std::string& path) {
  const toml::table tbl = TomlView::parse_text(text, path);
  const TomlView root(tbl, path);
  root.allow_only({"name", "description", "step"});
  Protocol p;
  p.name = root.get_string("name");
  // The text rule (common/text_rule.hpp): the name is recorded with every run and reaches the
  // report, the API and the fleet; the description is a note.
  if (const auto problem = identifier_problem(p.name)) throw root.error("name", *problem);
  p.description = root.opt_string("description").value_or("");
  if (const auto problem = note_problem(p.description, kMaxNoteBytes))
    throw root.error("description", *problem);
  p.path = path;
  p.text = text;
  for (const auto& sv : root.table_array("step")) p.steps.push_back(read_step(sv));
  if (p.steps.empty()) throw root.error("step", "a protocol needs at least one [[step]]");
  bool recording = false;
  for (std::size_t i = 0; i < p.steps.size(); ++i) {
    const auto& s = p.steps[i];
    const bool start = s.kind == StepKind::record_start, stop = s.kind == StepKind::record_stop;
    if ((start && recording) || (stop && !recording)) {
      throw InputError(fmt::format("{}:{}: key 'step[{}].type': {} while the record window is {}",
                                   path, s.line, i, to_string(s.kind),
                                   recording ? "open" : "closed"));
    }
    if (start || stop) recording = start;
  }
  check_tables_locked(p.steps, path);
  p.check_step_times(std::nullopt, std::nullopt);
  return p;
}

Protocol load_protocol(const std::string& file_or_name) {
  for (const auto& [name, text] : builtin::kProtocols) {
    if (name == file_or_name)
      return parse_protocol(std::string(text), "builtin:" + std::string(name));
  }
  std::ifstream in(file_or_name);
  if (!in) {
    throw InputError(fmt::format("{}: no such protocol file or shipped protocol (shipped: {})",
                                 file_or_name, fmt::join(builtin_protocol_names(), ", ")));
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_protocol(ss.str(), file_or_name);
}

std::vector<std::string> builtin_protocol_names() {
  std::vector<std::string> out;
  for (const auto& [name, text] : builtin::kProtocols) out.emplace_back(name);
  return out;
}

std::vector<std::optional<double>> Protocol::nominal_step_durations_s(
    std::optional<double> start_c) const {
  std::vector<std::optional<double>> out;
  std::optional<double> temp = start_c;  // the chamber's target when the step starts
  for (const auto& s : steps) {
    std::optional<double> d = 0.0;
    if (s.kind == StepKind::set_temperature) {
      const std::optional<double> target = s.to_start ? start_c : s.setpoint_c;
      if (s.ramp_c_per_h > 0)
        d = temp && target ? std::optional(std::abs(*target - *temp) / s.ramp_c_per_h * 3600.0)
                           : std::nullopt;
      temp = target;
    } else if (s.kind == StepKind::soak || s.kind == StepKind::hold) {
      d = s.duration_s;
    } else if (is_acceptance_step(s.kind)) {
      d = acceptance_duration_s(s);
    }
    out.push_back(d);
  }
  return out;
}

double Protocol::nominal_duration_s(double start_c) const {
  double t = 0;
  for (const auto& d : nominal_step_durations_s(start_c)) t += d.value_or(0.0);
  return t;
}

void Protocol::check_step_times(std::optional<double> lo_c, std::optional<double> hi_c) const {
  std::optional<double> temp;  // the chamber's temperature when the step starts, if fixed
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const Step& s = steps[i];
    if (s.kind != StepKind::set_temperature) continue;
    const std::optional<double> target = s.to_start ? std::nullopt : s.setpoint_c;
    std::optional<double> span_c;
    if (temp && target) {
      span_c = std::abs(*target - *temp);
    } else if (const auto known = target ? target : temp; known && lo_c && hi_c) {
      // The other end is the run's start temperature, somewhere within the limits.
      span_c = std::max(std::abs(*known - *lo_c), std::abs(*known - *hi_c));
    }
    const double ramp_s = s.ramp_c_per_h > 0 && span_c ? *span_c / s.ramp_c_per_h * 3600.0 : 0;
    if (ramp_s > kMaxStepS) {
      throw InputError(fmt::format(
          "{}:{}: key 'step[{}].ramp_c_per_h': {:g} C/h over {:g} C takes {:g} days, longer than "
          "the longest step ({:g} days)",
          path, s.ramp_line, i, s.ramp_c_per_h, *span_c, ramp_s / 86400.0, kMaxStepS / 86400.0));
    }
    temp = target;
  }
}

}  // namespace station
