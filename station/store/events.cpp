// The list of event kinds (see events.hpp; documented in schemas/events.md).
#include "station/store/events.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace station {

namespace {

using K = EventKind;

// One row per kind: name, severities, data fields, meaning. schemas/events.md has the same rows.
constexpr EventKindInfo kKinds[] = {
    {K::run_start, "run_start", "info", "protocol gyros", "a new run was created"},
    {K::run_end, "run_end", "info|warn", "state", "the run ended in `state` (runs.state)"},
    {K::aborted, "aborted", "warn", "",
     "a run left running was closed without bins or fit (not resumable)"},
    {K::run_failed, "run_failed", "error", "",
     "serve closed a run its daemon could not go on with"},
    {K::resume, "resume", "warn", "step_index last_s next_s",
     "a killed or restarted daemon continues the run"},
    {K::resume_gap, "resume_gap", "warn", "from_s to_s", "no samples while the daemon was down"},
    {K::tick_gap, "tick_gap", "warn", "start_s end_s ticks_lost", "ticks the daemon missed"},
    {K::detach, "detach", "info", "", "the run was left resumable for the next daemon"},
    {K::incomplete, "incomplete", "warn", "serial lost_ticks window_ticks",
     "a gyro lost more than max_lost_share of its record window"},
    {K::fit, "fit", "info", "serial", "a gyro's thermal model was fitted"},
    {K::fit_skipped, "fit_skipped", "warn", "", "a gyro could not be fitted"},
    {K::verdict, "verdict", "info|warn", "pass failed part checked context",
     "a fit judged against its part's limits"},
    {K::step_start, "step_start", "info", "step_index label line", "a protocol step begins"},
    {K::step_done, "step_done", "info", "step_index label after_s", "a protocol step is done"},
    {K::step_timeout, "step_timeout", "warn", "step_index label after_s",
     "a protocol step ran past its timeout"},
    {K::ramp_resume, "ramp_resume", "info", "from_c ramp_c_per_h",
     "a ramp goes on after a safe hold"},
    {K::record_start, "record_start", "info", "", "the record window opens"},
    {K::record_stop, "record_stop", "info", "", "the record window closes"},
    {K::acceptance_point, "acceptance_point", "info|warn",
     "step_index point demand measure_s end_s readings table_mean table_max_dev held",
     "a point of an acceptance step was measured"},
    {K::done, "done", "info", "", "the protocol is complete"},
    {K::connect, "connect", "warn", "", "a device could not be connected at the run's start"},
    {K::open, "open", "warn", "", "the GPIO bank could not be opened"},
    {K::outage_start, "outage_start", "warn", "device error", "a device stopped answering"},
    {K::outage, "outage", "warn|error", "device start_s end_s ticks_lost ended",
     "an outage ended: `ended` is `answered` (the device is back), `run_end` or `abort` (still "
     "down when the run ended)"},
    {K::board_reset, "board_reset", "warn", "serial", "a counter board restarted: re-baselined"},
    {K::counts_rebaselined, "counts_rebaselined", "warn", "serial",
     "a counter board's continuity is unproven: re-baselined"},
    {K::command_failed, "command_failed", "warn", "", "a device refused a protocol command"},
    {K::hold_failed, "hold_failed", "error", "", "the chamber refused the safe-hold command"},
    {K::stop_failed, "stop_failed", "error", "", "the turntable refused to stop"},
    {K::output_failed, "output_failed", "warn", "", "a GPIO output could not be written"},
    {K::edge, "edge", "info", "role rising", "a GPIO input changed"},
    {K::clamp, "clamp", "warn", "", "a setpoint or ramp was clamped to the station's limits"},
    {K::inputs_unreadable, "inputs_unreadable", "error", "",
     "interlock or e-stop unreadable: treated as open"},
    {K::safe_hold, "safe_hold", "error", "", "the rig entered safe hold"},
    {K::safe_hold_changed, "safe_hold_changed", "error", "", "the causes of a safe hold changed"},
    {K::safe_hold_cleared, "safe_hold_cleared", "info", "", "safe hold ended: the step resumes"},
    {K::sensor_fault, "sensor_fault", "error", "device sensor",
     "a device's sensor broke (chamber air: no reading, a safe hold)"},
    {K::sensor_fault_cleared, "sensor_fault_cleared", "info", "device sensor",
     "a broken sensor reads again"},
    {K::implausible_reading, "implausible_reading", "error", "device quantity value bound",
     "a reading no such device can give (its dialect's range, the limits widened): no value, the "
     "sample keeps it empty; a safe hold if it lasts as long as an unreadable input may"},
    {K::implausible_reading_end, "implausible_reading_end", "info", "device quantity ticks",
     "an implausible reading is plausible again after `ticks` ticks"},
    {K::setpoint_foreign, "setpoint_foreign", "warn|error", "read_c commanded_c action",
     "the chamber's setpoint reads other than the station commanded (the panel, another master): "
     "`action` `restore` (written again) or `hold` (a safe hold)"},
    {K::setpoint_foreign_end, "setpoint_foreign_end", "info", "read_c commanded_c",
     "the chamber's setpoint reads what the station commanded again"},
    {K::chamber_alarm, "chamber_alarm", "warn|error", "alarm",
     "a chamber alarm came on during a run (`alarm`: deviation, door_open, high_limit_trip, "
     "other)"},
    {K::chamber_alarm_cleared, "chamber_alarm_cleared", "info", "alarm",
     "a chamber alarm went off"},
    {K::listen, "listen", "info", "url", "where the live page is served"},
    {K::idle_fault, "idle_fault", "warn", "fault", "serve found the idle rig faulted"},
    {K::idle_clear, "idle_clear", "info", "was", "the idle rig's faults cleared"},
    {K::release, "release", "info|warn", "fit_id serial by override",
     "a fit was released as its gyro's calibration (warn: with an override)"},
    {K::verification, "verification", "info|warn", "verification_id fit_id",
     "a released fit was applied to an independent run"},
};

std::vector<std::string_view> words(std::string_view text, char sep) {
  std::vector<std::string_view> out;
  while (!text.empty()) {
    const auto at = text.find(sep);
    out.push_back(text.substr(0, at));
    if (at == std::string_view::npos) break;
    text.remove_prefix(at + 1);
  }
  return out;
}

}  // namespace

std::string_view to_string(Severity s) {
  switch (s) {
    case Severity::info:
      return "info";
    case Severity::warn:
      return "warn";
    case Severity::error:
      return "error";
  }
  return "error";
}

std::optional<Severity> parse_severity(std::string_view text) {
  for (const auto s : {Severity::info, Severity::warn, Severity::error})
    if (to_string(s) == text) return s;
  return std::nullopt;
}

std::span<const EventKindInfo> event_kinds() {
  return kKinds;
}

const EventKindInfo& info_of(EventKind k) {
  for (const auto& row : kKinds)
    if (row.kind == k) return row;
  throw std::logic_error("event kind without a row in events.cpp");
}

std::string_view to_string(EventKind k) {
  return info_of(k).name;
}

std::optional<EventKind> parse_event_kind(std::string_view name) {
  for (const auto& row : kKinds)
    if (row.name == name) return row.kind;
  return std::nullopt;
}

std::string event_mismatch(EventKind k, Severity s, const nlohmann::json& data) {
  const auto& row = info_of(k);
  const auto severities = words(row.severities, '|');
  if (std::find(severities.begin(), severities.end(), to_string(s)) == severities.end())
    return fmt::format("{}: severity {} is not one of {}", row.name, to_string(s), row.severities);
  const auto fields = words(row.data_fields, ' ');
  if (data.is_null())
    return fields.empty() ? "" : fmt::format("{}: no data, expected {}", row.name, row.data_fields);
  if (!data.is_object() || data.size() != fields.size())
    return fmt::format("{}: data {} is not an object of {}", row.name, data.dump(),
                       row.data_fields.empty() ? "nothing" : row.data_fields);
  for (const auto f : fields)
    if (!data.contains(std::string(f)))
      return fmt::format("{}: data {} lacks {}", row.name, data.dump(), f);
  return "";
}

}  // namespace station
