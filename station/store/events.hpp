// What the station's events are: one list of kinds, each with the severities it is stored with
// and the fields of its data (events.data_json). Code reads an event's kind and data; its
// message is for people. The list is documented in schemas/events.md (a unit test checks the
// document and this table are the same).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace station {

/// How much an event matters, stored as "info", "warn" or "error".
enum class Severity { info, warn, error };

std::string_view to_string(Severity s);
std::optional<Severity> parse_severity(std::string_view text);

/// Every kind of event the station stores (events.kind).
enum class EventKind {
  // The run (source "seq", "serve")
  run_start,
  run_end,
  aborted,
  run_failed,
  resume,
  resume_gap,
  tick_gap,
  detach,
  incomplete,
  fit,
  fit_skipped,
  verdict,
  // The protocol (source "seq")
  step_start,
  step_done,
  step_timeout,
  ramp_resume,
  record_start,
  record_stop,
  acceptance_point,
  done,
  // Devices (source: the device)
  connect,
  open,
  outage_start,
  outage,
  board_reset,
  counts_rebaselined,
  command_failed,
  hold_failed,
  stop_failed,
  output_failed,
  edge,
  // Safety (source "safety")
  clamp,
  inputs_unreadable,
  safe_hold,
  safe_hold_changed,
  safe_hold_cleared,
  sensor_fault,
  sensor_fault_cleared,
  implausible_reading,
  implausible_reading_end,
  setpoint_foreign,
  setpoint_foreign_end,
  chamber_alarm,
  chamber_alarm_cleared,
  // The service, releases and verification
  listen,
  idle_fault,
  idle_clear,
  release,
  verification,
};

/// One row of the list: the stored name, the severities it may have ("info|warn"), the names
/// of its data fields in order ("" when it carries none: data_json NULL) and what it means.
struct EventKindInfo {
  EventKind kind;
  std::string_view name;
  std::string_view severities;
  std::string_view data_fields;
  std::string_view meaning;
};

/// Every kind, in the order of schemas/events.md.
std::span<const EventKindInfo> event_kinds();
const EventKindInfo& info_of(EventKind k);
std::string_view to_string(EventKind k);
std::optional<EventKind> parse_event_kind(std::string_view name);

/// Why `data` does not fit kind `k`'s row (a field missing or extra, data where none is
/// listed, a severity not listed), or "" when it does.
std::string event_mismatch(EventKind k, Severity s, const nlohmann::json& data);

/// An event as a pure decision reports it (safety, the protocol runner); its caller stores it.
struct EventNote {
  Severity severity = Severity::info;
  EventKind kind = EventKind::done;
  std::string message;
  nlohmann::json data = nullptr;  ///< null, or an object with the kind's fields
};

}  // namespace station
