// The rules a request head must follow (see request_rules.hpp).
#include "station/http/request_rules.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <vector>

namespace station::http {

namespace {

/// The lines of a head without their terminators (CRLF or bare LF), the empty last one dropped.
std::vector<std::string_view> lines_of(std::string_view head) {
  std::vector<std::string_view> lines;
  while (!head.empty()) {
    const auto lf = head.find('\n');
    std::string_view line = head.substr(0, lf);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) break;  // the empty line that ends the head
    lines.push_back(line);
    if (lf == std::string_view::npos) break;
    head.remove_prefix(lf + 1);
  }
  return lines;
}

/// RFC 9110 §5.6.2: token = 1*tchar.
bool is_token(std::string_view s) {
  static constexpr std::string_view kSpecials = "!#$%&'*+-.^_`|~";
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || kSpecials.find(c) != kSpecials.npos;
  });
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

/// Content-Length's value: 1*DIGIT, or a list of them that all agree (RFC 9110 §8.6).
std::optional<std::string> content_length(std::string_view value) {
  std::optional<std::string> agreed;
  while (true) {
    const auto comma = value.find(',');
    const std::string_view one = trimmed(value.substr(0, comma));
    if (one.empty() || one.size() > 18 || !std::all_of(one.begin(), one.end(), ::isdigit))
      return std::nullopt;
    if (agreed && *agreed != one) return std::nullopt;
    agreed = std::string(one);
    if (comma == std::string_view::npos) return agreed;
    value.remove_prefix(comma + 1);
  }
}

/// An optional ":port" after a host: decimal digits, at most 5 (RFC 3986 §3.2.3).
bool port_ok(std::string_view rest) {
  if (rest.empty()) return true;
  if (rest.front() != ':') return false;
  rest.remove_prefix(1);
  return rest.size() <= 5 && std::all_of(rest.begin(), rest.end(), ::isdigit);
}

bool loopback_v6(const std::string& literal) {
  in6_addr a{};
  if (::inet_pton(AF_INET6, literal.c_str(), &a) != 1) return false;
  if (IN6_IS_ADDR_LOOPBACK(&a)) return true;
  return IN6_IS_ADDR_V4MAPPED(&a) && a.s6_addr[12] == 127;
}

}  // namespace

std::optional<std::size_t> head_end(std::string_view buffer) {
  for (std::size_t lf = buffer.find('\n'); lf != std::string_view::npos;
       lf = buffer.find('\n', lf + 1)) {
    // An empty line: "\n\n" or "\n\r\n" (a request line ending in LF alone counts too).
    if (lf + 1 < buffer.size() && buffer[lf + 1] == '\n') return lf + 2;
    if (lf + 2 < buffer.size() && buffer[lf + 1] == '\r' && buffer[lf + 2] == '\n') return lf + 3;
  }
  return std::nullopt;
}

HeadVerdict oversized_head(std::string_view buffer, const HeadLimits& limits) {
  if (buffer.substr(0, limits.max_bytes).find('\n') == std::string_view::npos)
    return {414, fmt::format("request line longer than {} bytes", limits.max_bytes)};
  return {431, fmt::format("request header fields larger than {} bytes", limits.max_bytes)};
}

HeadVerdict check_request_head(std::string_view head, const HeadLimits& limits) {
  const auto lines = lines_of(head);
  if (lines.size() > limits.max_fields + 1)
    return {431, fmt::format("more than {} header fields", limits.max_fields)};
  std::optional<std::string> length;
  bool host = false, chunked = false;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::string_view line = lines[i];
    if (line.front() == ' ' || line.front() == '\t')
      return {400, fmt::format("header line {}: obs-fold continuation line (RFC 9112 5.2)", i)};
    if (line.find_first_of(std::string_view("\0\r", 2)) != std::string_view::npos)
      return {400, fmt::format("header line {}: a NUL or bare CR (RFC 9110 5.5)", i)};
    const auto colon = line.find(':');
    if (colon == std::string_view::npos || !is_token(line.substr(0, colon)))
      return {400, fmt::format("header line {}: not 'name: value' (RFC 9112 5.1)", i)};
    const std::string_view name = line.substr(0, colon), value = trimmed(line.substr(colon + 1));
    if (iequals(name, "Host")) {
      if (host) return {400, "more than one Host header (RFC 9112 3.2)"};
      host = true;
    } else if (iequals(name, "Transfer-Encoding")) {
      chunked = true;
    } else if (iequals(name, "Content-Length")) {
      const auto n = content_length(value);
      if (!n || (length && *length != *n))
        return {400, "Content-Length invalid or given twice with different values (RFC 9110 8.6)"};
      length = n;
    }
  }
  if (length && chunked) return {400, "both Content-Length and Transfer-Encoding (RFC 9112 6.3)"};
  return {};
}

std::optional<std::string_view> field_value(std::string_view head, std::string_view name) {
  const auto lines = lines_of(head);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto colon = lines[i].find(':');
    if (colon != std::string_view::npos && iequals(lines[i].substr(0, colon), name))
      return trimmed(lines[i].substr(colon + 1));
  }
  return std::nullopt;
}

bool loopback_host(std::string_view host) {
  // Only what a loopback name, literal and port are made of: inet_pton reads a C string, so a
  // NUL ("127.0.0.1\0.evil.com", found by fuzz_request_head) must not reach it.
  static constexpr std::string_view kAllowed =
      "0123456789abcdefABCDEFlocLOC.:[]htsHTS";  // hex digits, "localhost", separators
  if (host.find_first_not_of(kAllowed) != std::string_view::npos) return false;
  if (host.starts_with('[')) {
    const auto close = host.find(']');
    return close != std::string_view::npos && port_ok(host.substr(close + 1)) &&
           loopback_v6(std::string(host.substr(1, close - 1)));
  }
  const auto colon = host.find(':');
  const std::string_view name = host.substr(0, colon);
  if (colon != std::string_view::npos && !port_ok(host.substr(colon))) return false;
  if (iequals(name, "localhost")) return true;
  in_addr a{};  // inet_pton takes dotted-decimal only: no "127.1", "0x7f.1" or trailing names
  return ::inet_pton(AF_INET, std::string(name).c_str(), &a) == 1 && (ntohl(a.s_addr) >> 24) == 127;
}

}  // namespace station::http
