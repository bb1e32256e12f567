// The simulated ACUTROL3000 (axis 1) over the table model: the ACL grammar parsed against the
// command tree transcribed from [ACL] (acl_parser.hpp, sources/acutrol_sources.hpp), errors in
// the status byte and the error message queue as [ACL] describes them, and replies framed bare
// (CR LF lines, [RN] p. 5) or with the error/length header ([ACL] p. 2, [RT] p. 34), as chosen.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "sim_devices/faces/acl_parser.hpp"
#include "sim_devices/servers/line_server.hpp"
#include "sim_devices/turntable_sim.hpp"

namespace station::sim {

/// How the simulated unit frames its replies.
enum class AclFraming { bare, header };
/// "bare" / "header"; nullopt for any other name.
std::optional<AclFraming> acl_framing_from_name(std::string_view name);

/// Serves: *IDN?, *CLS, *STB?, *ESR?; :Mode[?] and :Mode:Off/Position/Rate; :Demand:Position[?]
/// and :Demand:Rate[?]; :Read:Position? and :Read:Rate?; :Interlock?, :Interlock:Close/Open/
/// Reset; :Limit:Rate[?]; :Status:MSG?, :Status:STB?, :Status:MSGCLR; :Query:Error?. Any other
/// command of the tree parses and is refused as not simulated (ILLEGAL CMD).
class AcutrolFace final : public LineDevice {
 public:
  explicit AcutrolFace(TurntableSim& table, double rate_limit_dps = 1000.0,
                       AclFraming framing = AclFraming::bare);
  std::string request_terminator() const override { return "\n"; }  // a CR before it: dropped
  std::string reply_terminator() const override { return std::string(kBareEnd); }
  std::optional<std::string> handle(std::string_view request) override;
  /// An injected refusal: the request is refused with ILLEGAL CMD (the unit executes nothing),
  /// except the commands that read and clear errors, which answer as always.
  std::string error_reply(std::string_view request, int code) override;
  /// The reply as the chosen framing carries it.
  std::string encode(std::string reply) const override;

  /// The status byte as *STB? would read it now, without clearing it.
  unsigned status_byte() const;
  AclFraming framing() const { return framing_; }

  /// The error messages a queue holds at most; more are dropped (SUP0 "Error Queue Overflow",
  /// [ACL] p. 217).
  static constexpr std::size_t kQueueMax = 32;

 private:
  static constexpr std::string_view kBareEnd = "\r\n";

  /// One unit's reply text (empty for a command), or its error.
  std::string run(const AclUnit& u, std::uint32_t& error, std::string& why);
  std::string common(const AclUnit& u, std::uint32_t& error, std::string& why);
  std::string mode(const AclUnit& u, std::uint32_t& error, std::string& why);
  std::string motion(const AclUnit& u, std::uint32_t& error, std::string& why);
  std::string demand(const AclUnit& u, std::uint32_t& error, std::string& why);
  std::string status(const AclUnit& u, std::uint32_t& error, std::string& why);
  /// Queues the error, sets the status byte's bit and the reply's error code.
  void raise(std::uint32_t code, const std::string& path, const std::string& why);
  /// True when every unit of the message reads or clears errors (answered during a refusal).
  static bool reads_errors(const std::vector<AclUnit>& units);

  TurntableSim& table_;
  AclFraming framing_;
  std::map<std::string, double> rate_limit_dps_;  // per mode, as :Limit:Rate sets it
  bool interlock_closed_ = false;
  std::deque<std::string> errors_;  // the error message queue (QERROR)
  unsigned latched_ = 0;            // status byte bits set since the last *STB?
  std::uint32_t reply_code_ = 0;    // the error code of the reply being built
};

}  // namespace station::sim
