// What a request's head must be before the server reads it further (pure: text in, verdict
// out). The rules are HTTP/1.1's own (RFC 9110, RFC 9112) with the limits of schemas/api.md;
// the server (bounded_server.cpp) reads the head under them, before any route or token check.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace station::http {

/// The limits of one request head (schemas/api.md, "Limits").
struct HeadLimits {
  std::size_t max_bytes = 8 * 1024;  ///< request line and header fields, CRLFs included
  std::size_t max_fields = 100;      ///< header field lines
};

/// A head's verdict: status 0 when it may be served, else the status to answer and why.
struct HeadVerdict {
  int status = 0;
  std::string reason;
};

/// Where the head in `buffer` ends (the index after its empty line; CRLF or a bare LF, RFC 9112
/// §2.2), or nullopt while it is incomplete.
std::optional<std::size_t> head_end(std::string_view buffer);

/// The verdict on a head that did not end within `limits.max_bytes`: 414 when even the request
/// line did not (RFC 9112 §3), else 431 (RFC 6585 §5).
HeadVerdict oversized_head(std::string_view buffer, const HeadLimits& limits);

/// Checks a complete head (as cut by head_end): at most `max_fields` fields (431); each field
/// line `name:value` with a token name and no whitespace before the colon (RFC 9112 §5.1), no
/// NUL or bare CR in it (RFC 9110 §5.5), no
/// obs-fold continuation line (§5.2), one Host at most (§3.2), Content-Length a decimal number
/// whose repeats all agree (RFC 9110 §8.6), not beside Transfer-Encoding (RFC 9112 §6.3): 400.
HeadVerdict check_request_head(std::string_view head, const HeadLimits& limits);

/// The value of the first field called `name` (any case) of a complete head, trimmed; nullopt
/// when it has none.
std::optional<std::string_view> field_value(std::string_view head, std::string_view name);

/// Whether a Host header value names this machine's loopback: exactly `localhost` (any case),
/// an IPv4 literal in 127.0.0.0/8 or the IPv6 literal [::1] (or [::ffff:127.x.y.z]), each with
/// an optional decimal port (RFC 9110 §7.2, RFC 3986 §3.2.2). A name that merely starts with
/// "127." (127.evil.com, 127.0.0.1.nip.io) is not: DNS rebinding sends the attacker's name.
bool loopback_host(std::string_view host);

}  // namespace station::http
