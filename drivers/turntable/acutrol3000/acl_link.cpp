// AclLink: framing, refusals and the status reads of the ACUTROL command language.
#include "drivers/turntable/acutrol3000/acl_link.hpp"

#include <fmt/format.h>

namespace station::drivers::acutrol3000 {
namespace {

// A reply's text without the CR LF a unit may end it with ([RN] p. 5).
std::string text_of(std::string payload) {
  while (!payload.empty() && (payload.back() == '\r' || payload.back() == '\n')) payload.pop_back();
  return payload;
}

}  // namespace

AclLink::AclLink(std::string name, ascii::LineEndpoint endpoint, double timeout_s, Framing framing,
                 std::unique_ptr<ascii::LineWire> wire)
    : name_(name),
      client_(std::move(name), std::move(endpoint),
              ascii::LineFraming{std::string(kCommandTerminator), std::string(kReplyTerminator),
                                 kFrame.max_payload_bytes},
              std::move(wire), timeout_s),
      configured_(framing) {}

Result<void> AclLink::connect() {
  if (auto c = client_.connect(); !c) return c;
  return prepare();
}

Result<void> AclLink::prepare() {
  if (client_.connected() && in_use_ && prepared_connects_ == client_.connects()) return {};
  in_use_.reset();
  if (configured_ != Framing::automatic) {
    in_use_ = configured_;
  } else {
    // A frame's header holds NUL bytes, text never does ([RT] p. 34, [ACL] p. 2).
    auto idn = client_.query_detect(kIdentify, kFrame);
    if (!idn) return idn.error();
    in_use_ = idn.value().framed() ? Framing::header : Framing::bare;
  }
  // An error queued before this connection must not be read as this connection's refusal.
  auto cls = exchange(kClearStatus);
  if (!cls) {
    in_use_.reset();
    return cls.error();
  }
  prepared_connects_ = client_.connects();
  if (cls.value().framed() && frame_error_code(cls.value().header) != 0)
    return refused_by_code(kClearStatus, frame_error_code(cls.value().header));
  return {};
}

Result<ascii::Reply> AclLink::exchange(std::string_view request) {
  if (in_use_ == Framing::header) return client_.query_frame(request, kFrame);
  auto line = client_.query(request);
  if (!line) return line.error();
  ascii::Reply r;
  r.payload = std::move(line).value();
  return r;
}

Result<std::optional<std::string>> AclLink::queued_error() {
  auto stb = exchange(kStatusByteQuery);
  if (!stb) return stb.error();
  const std::string stb_text = text_of(stb.value().payload);
  const auto status = parse_status_byte(stb_text);
  if (!status)
    return make_error(ErrorKind::protocol, fmt::format("{}: status byte '{}' (reply to {}) is not "
                                                       "a number 0..255",
                                                       name_, stb_text, kStatusByteQuery));
  if ((*status & kErrorQueueBit) == 0) return std::optional<std::string>();
  auto msg = exchange(kErrorQueueRead);
  if (!msg) return msg.error();
  if (auto cls = exchange(kClearStatus); !cls) return cls.error();
  std::string why = text_of(msg.value().payload);
  if (why.empty()) why = fmt::format("error queue bit set (status byte {}), queue empty", *status);
  return std::optional<std::string>(std::move(why));
}

Error AclLink::refused(std::string_view request, const std::string& reason) const {
  return make_error(ErrorKind::exception,
                    fmt::format("{}: '{}' refused by the unit: {}", name_, request, reason));
}

Error AclLink::refused_by_code(std::string_view request, std::uint32_t code) {
  // The description, if the unit gives one ([ACL] p. 163); the code alone otherwise.
  std::string why = fmt::format("error code {}", code);
  if (auto text = exchange(error_text_query(code));
      text && frame_error_code(text.value().header) == 0 && !text_of(text.value().payload).empty())
    why += " (" + text_of(text.value().payload) + ")";
  (void)exchange(kClearStatus);  // the unit queued it too ([ACL] p. 178): read, so cleared
  return refused(request, why);
}

Result<std::string> AclLink::query(std::string_view q, Parses parses) {
  if (auto p = prepare(); !p) return p.error();
  auto r = exchange(q);
  if (!r) return r.error();
  if (r.value().framed()) {
    if (const auto code = frame_error_code(r.value().header); code != 0)
      return refused_by_code(q, code);
  }
  std::string text = text_of(std::move(r.value().payload));
  if (!text.empty() && parses(text)) return text;
  if (!r.value().framed()) {  // a bare refusal answers nothing a parser takes: ask the status
    auto why = queued_error();
    if (!why) return why.error();
    if (why.value()) return refused(q, *why.value());
  }
  return make_error(ErrorKind::protocol,
                    fmt::format("{}: reply '{}' to '{}' does not parse", name_, text, q));
}

Result<void> AclLink::command(std::string_view c) {
  if (auto p = prepare(); !p) return p.error();
  auto r = exchange(c);
  if (!r) return r.error();
  if (r.value().framed()) {
    if (const auto code = frame_error_code(r.value().header); code != 0)
      return refused_by_code(c, code);
    return {};
  }
  auto why = queued_error();
  if (!why) return why.error();
  if (why.value()) return refused(c, *why.value());
  if (const std::string text = text_of(r.value().payload); !text.empty())
    return make_error(ErrorKind::protocol,
                      fmt::format("{}: '{}' answered '{}' where an empty acknowledgement was "
                                  "expected ([RN] p. 5)",
                                  name_, c, text));
  return {};
}

}  // namespace station::drivers::acutrol3000
