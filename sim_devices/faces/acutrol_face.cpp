// AcutrolFace: ACL messages executed on the table model, errors queued, replies framed.
#include "sim_devices/faces/acutrol_face.hpp"

#include <fmt/format.h>

namespace station::sim {
namespace {

namespace src = sources::acutrol;

std::string le32(std::uint32_t v) {
  std::string out(4, '\0');
  for (int i = 0; i < 4; ++i) out[static_cast<std::size_t>(i)] = static_cast<char>(v >> (8 * i));
  return out;
}

constexpr std::string_view kNotSimulated = "not simulated";

}  // namespace

std::optional<AclFraming> acl_framing_from_name(std::string_view name) {
  if (name == "bare") return AclFraming::bare;
  if (name == "header") return AclFraming::header;
  return std::nullopt;
}

AcutrolFace::AcutrolFace(TurntableSim& table, double rate_limit_dps, AclFraming framing)
    : table_(table), framing_(framing) {
  for (std::string_view m : src::kModes) rate_limit_dps_[std::string(m)] = rate_limit_dps;
}

unsigned AcutrolFace::status_byte() const {
  // EQ while the queue holds a message ([ACL] p. 178: "remains true as long as the queue is not
  // empty"); SI while an interlock is tripped; MSS when any other bit is set (p. 19-20).
  unsigned b = errors_.empty() ? 0 : src::kStbErrorQueue;
  if (table_.fault() || table_.interlock_open()) b |= src::kStbInterlocks;
  return b != 0 ? b | src::kStbMss : 0;
}

void AcutrolFace::raise(std::uint32_t code, const std::string& path, const std::string& why) {
  if (reply_code_ == 0) reply_code_ = code;
  if (errors_.size() < kQueueMax)
    errors_.push_back(fmt::format("{},{}: {} {}", code, src::error_text(code), path, why));
}

std::optional<std::string> AcutrolFace::handle(std::string_view request) {
  if (!request.empty() && request.back() == '\r') request.remove_suffix(1);
  reply_code_ = 0;
  std::string out;
  bool first = true;
  for (const AclUnit& u : parse_acl(request)) {
    std::uint32_t error = u.error;
    std::string why = u.why;
    const std::string reply = error == 0 ? run(u, error, why) : std::string();
    if (error != 0) {
      raise(error, u.path.empty() ? u.text : u.path, why);
      break;  // the rest of the message is not executed (the simulator's choice)
    }
    if (u.query) out += (first ? "" : ";") + reply, first = false;
  }
  return out;
}

bool AcutrolFace::reads_errors(const std::vector<AclUnit>& units) {
  for (const AclUnit& u : units) {
    const std::string_view p = u.path;
    if (u.error != 0 || !(p == "*STB" || p == "*CLS" || p == "*IDN" || p.starts_with(":Status:") ||
                          p == ":Query:Error"))
      return false;
  }
  return !units.empty();
}

std::string AcutrolFace::error_reply(std::string_view request, int) {
  std::string_view r = request;
  if (!r.empty() && r.back() == '\r') r.remove_suffix(1);
  const auto units = parse_acl(r);
  if (reads_errors(units)) return *handle(request);
  reply_code_ = 0;
  raise(src::kIllegalCommand.code, units.empty() ? std::string(r) : units.front().path,
        "refused: the unit executes no command now (injected fault)");
  return {};
}

std::string AcutrolFace::encode(std::string reply) const {
  if (framing_ == AclFraming::bare) return reply + std::string(kBareEnd);
  return le32(reply_code_) + le32(static_cast<std::uint32_t>(reply.size())) + reply + '\0';
}

std::string AcutrolFace::run(const AclUnit& u, std::uint32_t& error, std::string& why) {
  const std::string& p = u.path;
  if (!p.empty() && p.front() == '*') return common(u, error, why);
  if (p == ":Mode" || p.starts_with(":Mode:")) return mode(u, error, why);
  if (p.starts_with(":Status:") || p == ":Query:Error") return status(u, error, why);
  if (p == ":Demand:Position" || p == ":Demand:Rate") return demand(u, error, why);
  // The rest motion() serves, or refuses as not simulated.
  return motion(u, error, why);
}

std::string AcutrolFace::common(const AclUnit& u, std::uint32_t& error, std::string& why) {
  if (u.path == "*IDN") return std::string(src::kIdentity);
  if (u.path == "*STB") return std::to_string(status_byte());
  if (u.path == "*ESR") return "0";
  if (u.path == "*CLS") {
    errors_.clear();
    return {};
  }
  error = src::kIllegalCommand.code;
  why = std::string(kNotSimulated);
  return {};
}

}  // namespace station::sim
