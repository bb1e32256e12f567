// `station probe` while the rig is in use (probe_in_use.hpp).
#include "station/cli/probe_in_use.hpp"

#include <fmt/format.h>

#include <sstream>

#include "station/cli/exit_status.hpp"

namespace station {
namespace {

using nlohmann::json;

// A number of the status, or "?" when the station did not read it this tick.
std::string num(const json& j, const char* key, const char* format) {
  const auto& v = j.value(key, json());
  return v.is_number() ? fmt::format(fmt::runtime(format), v.get<double>()) : std::string("?");
}

std::string yes_no(const json& v) {
  return v.is_boolean() ? (v.get<bool>() ? "yes" : "no") : "?";
}

std::string run_line(const json& s) {
  const auto& run = s.value("run", json());
  std::string line = "state " + s.value("state", std::string("?"));
  if (run.is_object())
    line +=
        fmt::format(": run {}, protocol {}, step {} '{}', t = {} s", run.value("id", json()).dump(),
                    run.value("protocol", std::string()), run.value("step_index", 0) + 1,
                    run.value("step_label", std::string()), num(run, "t_s", "{:.0f}"));
  if (s.contains("fault")) line += fmt::format(" ({})", s["fault"].get<std::string>());
  return line;
}

void print_devices(const json& s, std::ostream& out) {
  const auto& c = s.value("chamber", json());
  out << (c.is_object()
              ? fmt::format("{:<16} air {} C, setpoint {} C, {}, alarm {}\n", "chamber",
                            num(c, "air_c", "{:.2f}"), num(c, "setpoint_c", "{:.2f}"),
                            c.value("mode", std::string()), yes_no(c.value("alarm", json())))
              : fmt::format("{:<16} not read this tick\n", "chamber"));
  const auto& t = s.value("table", json());
  if (t.is_object())
    out << fmt::format("{:<16} angle {} deg, rate {} deg/s, locked {}, {}\n", "turntable",
                       num(t, "angle_deg", "{:.3f}"), num(t, "rate_dps", "{:.4f}"),
                       yes_no(t.value("locked", json())), t.value("mode", std::string()));
  const auto& slots = s.value("slots", json::array());
  if (slots.empty())  // between runs the station does not read the counter boards
    for (const auto& r : s.value("rig_slots", json::array()))
      out << fmt::format("{:<16} node {}: counter boards are read during a run only\n",
                         "slot " + r.value("serial", std::string("?")),
                         r.value("node", json()).dump());
  for (const auto& g : slots)
    out << fmt::format("{:<16} rate {} deg/h, temperature {} C, gradient {} C\n",
                       "slot " + g.value("serial", std::string("?")), num(g, "rate_dph", "{:.3f}"),
                       num(g, "temp_c", "{:.2f}"), num(g, "grad_c", "{:.3f}"));
  const auto& safety = s.value("safety", json());
  if (safety.is_object())
    out << fmt::format("{:<16} door closed {}, e-stop pressed {}, safe hold {}\n", "safety",
                       yes_no(safety.value("door_closed", json())),
                       yes_no(safety.value("estop_pressed", json())),
                       yes_no(safety.value("safe_hold", json())));
}

}  // namespace

int daemon_view_status(const json& s) {
  if (s.value("state", std::string()) == "fault") return kExitFailure;
  if (!s.value("chamber", json()).is_object()) return kExitFailure;
  for (const auto& g : s.value("slots", json::array()))
    if (!g.value("rate_dph", json()).is_number()) return kExitFailure;
  return kExitOk;
}

namespace {

// The answer refused when it is not from the process holding the rig (its "pid" another than
// the lock's) or not a station's status (a field of another type): the error says which.
http::StatusAnswer checked(http::StatusAnswer a, const std::string& holder_pid) {
  if (!a.status) return a;
  try {
    const auto& pid = a.status->value("pid", json());
    if (!holder_pid.empty() && pid.is_number_integer() &&
        std::to_string(pid.get<long>()) != holder_pid) {
      a.error = fmt::format(
          "the station answering there is pid {}, not the rig's holder (pid {}): give --http "
          "where pid {} serves",
          pid.get<long>(), holder_pid, holder_pid);
      a.status.reset();
      return a;
    }
    std::ostringstream trial;  // every field read as the view reads it
    trial << run_line(*a.status);
    print_devices(*a.status, trial);
    daemon_view_status(*a.status);
  } catch (const json::exception& e) {
    a.error = fmt::format("not a station's status: {}", e.what());
    a.status.reset();
  }
  return a;
}

}  // namespace

int print_daemon_view(const std::string& holder, const std::string& holder_pid,
                      const http::StatusAnswer& answer, std::ostream& out, bool json_out) {
  const http::StatusAnswer a = checked(answer, holder_pid);
  const int code = a.status ? daemon_view_status(*a.status) : kExitInput;
  if (json_out) {
    json j{{"in_use", holder}, {"asked", a.url}, {"ok", code == kExitOk}, {"devices_read", false}};
    if (a.status)
      j["status"] = *a.status;
    else
      j["error"] = a.error;
    out << j.dump(2, ' ', false, json::error_handler_t::replace) << '\n';
    return code;
  }
  out << fmt::format(
      "rig in use: {}\nprobe reads none of its devices (the running station owns "
      "them); asking {}\n",
      holder, a.url);
  if (!a.status) {
    out << fmt::format(
        "no usable answer: {} (a `run` without --http serves none; give probe --http "
        "HOST:PORT where it serves)\n",
        a.error);
    return code;
  }
  out << fmt::format("what '{}' sees: {}\n", a.status->value("station", std::string("?")),
                     run_line(*a.status));
  print_devices(*a.status, out);
  out << (code == kExitOk ? "every device the station reads answered this tick\n"
                          : "the station does not read every device (see above)\n");
  return code;
}

}  // namespace station
