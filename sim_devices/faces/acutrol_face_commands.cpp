// AcutrolFace: the commands the simulated unit executes on the table model ([ACL] §4.3, 4.5-4.7,
// 4.9-4.11; pages in sources/acutrol_sources.cpp). Errors as the pages list them: an invalid
// axis, mode or value sets PARAMETER OUT OF RANGE; what the unit cannot do now, ILLEGAL CMD.
#include <fmt/format.h>

#include <cmath>

#include "drivers/ascii/number_field.hpp"
#include "sim_devices/faces/acutrol_face.hpp"

namespace station::sim {
namespace {

namespace src = sources::acutrol;

std::string fmt5(double v) {
  return fmt::format("{:.5f}", v);
}

// Fills the error of a bad argument; always false.
bool bad(std::uint32_t& error, std::string& why, std::string what) {
  error = src::kParameterOutOfRange.code;
  why = std::move(what);
  return false;
}

// The argument count a form takes, and the axis among them: "1", or "ALL" for a command (p. 4).
bool axis_args(const AclUnit& u, std::size_t axis_at, std::size_t count, std::uint32_t& error,
               std::string& why) {
  if (u.args.size() != count)
    return bad(error, why, fmt::format("takes {} argument(s), got {}", count, u.args.size()));
  const std::string& a = u.args[axis_at];
  if (a == "1" || (!u.query && acl_abbreviates(a, "ALL") && a.size() == 3)) return true;
  return bad(error, why, fmt::format("axis '{}' (the table has axis 1)", a));
}

// A <mode> argument: any prefix of a mode's name, any case, the first in [ACL] p. 147's order.
std::optional<std::string> mode_word(std::string_view arg) {
  for (std::string_view m : src::kModes)
    if (acl_abbreviates(arg, m)) return std::string(m);
  return std::nullopt;
}

}  // namespace

std::string AcutrolFace::mode(const AclUnit& u, std::uint32_t& error, std::string& why) {
  std::string word;
  if (u.path == ":Mode") {
    if (u.query) {  // :Mode? <axis> (p. 147); the word as [py] :121 reads it
      if (!axis_args(u, 0, 1, error, why)) return {};
      const int m = table_.mode();
      return m == 1 ? "Position" : m == 2 ? "Rate" : "Off";
    }
    if (!axis_args(u, 0, 2, error, why)) return {};  // :Mode <axis|ALL>,<mode>
    const auto w = mode_word(u.args[1]);
    if (!w) return bad(error, why, fmt::format("mode '{}'", u.args[1])), std::string();
    word = *w;
  } else {  // :Mode:Off <axis> ... (p. 148-154)
    if (!axis_args(u, 0, 1, error, why)) return {};
    word = u.path.substr(u.path.rfind(':') + 1);
  }
  if (word == "Off") {  // always taken: with the interlock open the axis is off already
    (void)table_.set_mode(0);
    return {};
  }
  if (word != "Position" && word != "Rate") {
    error = src::kIllegalCommand.code;
    why = fmt::format("mode {} not simulated", word);
    return {};
  }
  if (!interlock_closed_ || !table_.set_mode(word == "Position" ? 1 : 2)) {
    error = src::kIllegalCommand.code;
    why = "interlock open: the axis is not servoed (:Interlock:Close)";
  }
  return {};
}

std::string AcutrolFace::motion(const AclUnit& u, std::uint32_t& error, std::string& why) {
  const std::string& p = u.path;
  const bool tripped = table_.fault() || table_.interlock_open();
  if (p == ":Read:Position" || p == ":Read:Rate") {  // p. 168-169
    if (!axis_args(u, 0, 1, error, why)) return {};
    return fmt5(p == ":Read:Position" ? table_.angle_deg() : table_.shown_rate_dps());
  }
  if (p == ":Interlock") {  // Close / Open / Fault ([ACL] p. 133's words; [py] :41)
    if (!axis_args(u, 0, 1, error, why)) return {};
    return tripped ? "Fault" : interlock_closed_ ? "Close" : "Open";
  }
  if (p == ":Interlock:Reset") return {};  // p. 136: clears nothing the model latches
  if (p == ":Interlock:Close" || p == ":Interlock:Open") {  // p. 131, 135
    if (!axis_args(u, 0, 1, error, why)) return {};
    interlock_closed_ = p == ":Interlock:Close" && !tripped;
    if (!interlock_closed_) (void)table_.set_mode(0);
    return {};
  }
  if (p == ":Limit:Rate") {  // <mode>,<axis>[,<rate limit>] (p. 145)
    if (!axis_args(u, 1, u.query ? 2 : 3, error, why)) return {};
    const auto m = mode_word(u.args[0]);
    if (!m) return bad(error, why, fmt::format("mode '{}'", u.args[0])), std::string();
    if (u.query) return fmt5(rate_limit_dps_[*m]);
    const auto v = drivers::ascii::number_field(u.args[2]);
    if (!v || *v <= 0) return bad(error, why, fmt::format("rate limit '{}'", u.args[2])), "";
    rate_limit_dps_[*m] = *v;
    return {};
  }
  error = src::kIllegalCommand.code;
  why = "not simulated";
  return {};
}

// :Demand:Position[?] and :Demand:Rate[?] <axis>[,<value>] (p. 112-113).
std::string AcutrolFace::demand(const AclUnit& u, std::uint32_t& error, std::string& why) {
  const bool position = u.path == ":Demand:Position";
  if (!axis_args(u, 0, u.query ? 1 : 2, error, why)) return {};
  if (u.query) return fmt5(position ? table_.position_demand_deg() : table_.rate_demand_dps());
  const auto v = drivers::ascii::number_field(u.args[1]);
  if (!v) return bad(error, why, fmt::format("value '{}'", u.args[1])), std::string();
  if (position) {
    table_.set_position_demand_deg(*v);
  } else if (std::abs(*v) > rate_limit_dps_["Rate"]) {
    bad(error, why, fmt::format("rate {} beyond the rate limit {}", *v, rate_limit_dps_["Rate"]));
  } else {
    table_.set_rate_demand_dps(*v);
  }
  return {};
}

std::string AcutrolFace::status(const AclUnit& u, std::uint32_t& error, std::string& why) {
  const std::string& p = u.path;
  if (p == ":Status:STB") return std::to_string(status_byte());  // p. 180: not cleared
  if (p == ":Query:Error") {                                     // p. 163
    if (u.args.size() != 1) return bad(error, why, "takes an error code"), std::string();
    const auto code = drivers::ascii::number_field(u.args[0]);
    if (!code || *code < 0 || *code > 4e9) return bad(error, why, "error code"), std::string();
    return std::string(src::error_text(static_cast<std::uint32_t>(*code)));
  }
  const bool errors = !u.args.empty() && (acl_abbreviates(u.args[0], src::kErrorQueueId) &&
                                          u.args[0].size() == src::kErrorQueueId.size());
  if (p == ":Status:MSGCLR") {  // p. 179: <qid|All>
    if (errors || (!u.args.empty() && acl_abbreviates(u.args[0], "All"))) errors_.clear();
    return {};
  }
  if (p == ":Status:MSG") {  // p. 178: <qid>[,<n>|,ALL]; an empty queue reads a null string
    if (u.args.empty() || u.args.size() > 2) return bad(error, why, "takes <qid>[,<n>|ALL]"), "";
    std::size_t n = 1;
    if (u.args.size() == 2)
      n = acl_abbreviates(u.args[1], "ALL")
              ? errors_.size()
              : static_cast<std::size_t>(
                    std::max(0.0, drivers::ascii::number_field(u.args[1]).value_or(1.0)));
    std::string out;
    for (; errors && n > 0 && !errors_.empty(); --n, errors_.pop_front())
      out += (out.empty() ? "" : ";") + errors_.front();
    return out;
  }
  error = src::kIllegalCommand.code;
  why = "not simulated";
  return {};
}

}  // namespace station::sim
