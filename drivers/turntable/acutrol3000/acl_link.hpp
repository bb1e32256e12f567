// The ACUTROL's command-language link: a LineClient, the unit's reply framing (configured, or
// recognized at connect from the reply to *IDN?) and its errors read as ACL reports them, so a
// refused command is never taken for success (acutrol_wire.hpp names the sources). Bare lines:
// after every command the status byte's error-queue bit, and the queue's message when it is set;
// after a query only when its reply is empty or does not parse (queries run every tick).
// Header frames: the error code of every reply (and the status cleared after a refusal). Not
// thread-safe; the constructor does no I/O.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "drivers/ascii/line_client.hpp"
#include "drivers/turntable/acutrol3000/acutrol_wire.hpp"

namespace station::drivers::acutrol3000 {

class AclLink {
 public:
  /// Accepts a reply's text (a parser of acutrol_wire.hpp).
  using Parses = bool (*)(std::string_view);

  AclLink(std::string name, ascii::LineEndpoint endpoint, double timeout_s, Framing framing,
          std::unique_ptr<ascii::LineWire> wire);

  /// Opens the link now (whatever the back-off says) and prepares it; blocks up to the timeout
  /// per exchange.
  Result<void> connect();
  /// Sends query `q`; its reply's text (CR LF removed) once `parses` takes it. A refusal is
  /// ErrorKind::exception naming the query and the unit's reason; a reply that neither parses
  /// nor is a refusal is ErrorKind::protocol.
  Result<std::string> query(std::string_view q, Parses parses);
  /// Sends command `c` (no data in reply: an empty acknowledgement, [RN] p. 5) and reads whether
  /// the unit refused it (ErrorKind::exception naming the command and the reason).
  Result<void> command(std::string_view c);

  /// The framing configured, and the one in use on this connection (nullopt before it is known).
  Framing framing() const { return configured_; }
  std::optional<Framing> framing_in_use() const { return in_use_; }
  /// Successful connects so far (a change tells the driver the unit may have restarted).
  std::uint64_t connects() const { return client_.connects(); }
  void set_tap(Tap* tap) { client_.set_tap(tap); }
  void set_clock(const Clock* clock) { client_.set_clock(clock); }

 private:
  /// On a new connection: the framing recognized (auto) and stale status cleared (*CLS).
  Result<void> prepare();
  /// One request in the framing in use: a frame, or a line as a payload without header.
  Result<ascii::Reply> exchange(std::string_view request);
  /// Bare lines: the error queue's message when the status byte says one is queued, else
  /// nullopt; the status is cleared after reading it (*CLS).
  Result<std::optional<std::string>> queued_error();
  /// The refusal of `request`: reason in words, and the error code when a header carried it.
  Error refused(std::string_view request, const std::string& reason) const;
  Error refused_by_code(std::string_view request, std::uint32_t code);

  std::string name_;
  ascii::LineClient client_;
  Framing configured_;
  std::optional<Framing> in_use_;
  std::uint64_t prepared_connects_ = 0;  // the connection prepare() last ran on
};

}  // namespace station::drivers::acutrol3000
