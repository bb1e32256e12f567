// LineClient: length-prefixed frames, and a reply recognized as a frame or a line by its first
// bytes. Every byte read is tapped once the reads are done, before the frame is judged, so a
// recorded session replays the same judgement from the same bytes.
#include <fmt/format.h>

#include <cerrno>
#include <cstdint>

#include "drivers/ascii/line_client.hpp"
#include "drivers/common/exchange_deadline.hpp"

namespace station::drivers::ascii {
namespace {

std::uint32_t little_endian_u32(std::string_view b) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[i]);
  return v;
}

}  // namespace

Error LineClient::malformed(std::string_view command, const std::string& what) {
  wire_->flush();  // the rest of a broken reply must not be read as the next one
  return make_error(ErrorKind::protocol,
                    fmt::format("{} reply to '{}': {}", device_, command, what));
}

Result<Reply> LineClient::finish_frame(std::string_view command, const FrameLayout& layout,
                                       std::string raw, double deadline_s) {
  const auto read = [&](std::size_t n) {
    std::string more;
    if (n > 0 && wire_->receive_exact(more, n, seconds_left(deadline_s)) == -1) return false;
    raw += more;
    return true;
  };
  const auto failed = [&] {
    // Silence after part of a frame: a reply cut short (EBADMSG), not a silent device.
    const int err = errno == ETIMEDOUT && !raw.empty() ? EBADMSG : errno;
    return fail(err, fmt::format("reply to '{}'", command));
  };
  if (raw.size() < layout.header_bytes && !read(layout.header_bytes - raw.size())) return failed();
  const std::uint32_t length = little_endian_u32(raw.substr(layout.length_offset, 4));
  const bool too_long = length > layout.max_payload_bytes;
  // The payload, then the NUL: counted in the length (the payload ends in it) or after it.
  if (!too_long && !read(length)) return failed();
  const bool nul_counted = length > 0 && raw.back() == '\0';
  if (!too_long && !nul_counted && !read(1)) return failed();
  link_.answered();
  tap(TapDirection::rx, "ascii", raw, {});
  if (too_long)
    return malformed(command, fmt::format("frame length {} beyond the {} a frame may carry", length,
                                          layout.max_payload_bytes));
  if (raw.back() != '\0')
    return malformed(command, fmt::format("frame of {} bytes not ended by a NUL", length));
  Reply r;
  r.header = raw.substr(0, layout.header_bytes);
  r.payload = raw.substr(layout.header_bytes, raw.size() - layout.header_bytes - 1);
  return r;
}

Result<Reply> LineClient::finish_line(std::string_view command, std::string raw,
                                      double deadline_s) {
  const std::string& end = framing_.reply_terminator;
  if (!raw.ends_with(end)) {
    std::string rest;
    if (wire_->receive(rest, end, seconds_left(deadline_s), framing_.max_reply_bytes) == -1) {
      const int err = errno;
      return fail(err, fmt::format("reply to '{}'", command));
    }
    raw += rest + end;
  }
  link_.answered();
  tap(TapDirection::rx, "ascii", raw, {});
  Reply r;
  r.payload = raw.substr(0, raw.size() - end.size());
  return r;
}

Result<Reply> LineClient::query_frame(std::string_view command, const FrameLayout& layout) {
  const double deadline_s = ExchangeDeadline::bound_s(deadline_after(timeout_s_));
  if (auto t = transmit(command, seconds_left(deadline_s)); !t) return t.error();
  return finish_frame(command, layout, {}, deadline_s);
}

Result<Reply> LineClient::query_detect(std::string_view command, const FrameLayout& layout) {
  const double deadline_s = ExchangeDeadline::bound_s(deadline_after(timeout_s_));
  if (auto t = transmit(command, seconds_left(deadline_s)); !t) return t.error();
  // Byte by byte until a NUL (a frame's header), the line's end, or a header's worth of text.
  std::string raw;
  while (raw.size() < layout.header_bytes && !raw.ends_with(framing_.reply_terminator)) {
    std::string b;
    if (wire_->receive_exact(b, 1, seconds_left(deadline_s)) == -1) {
      const int err = errno;
      return fail(err, fmt::format("reply to '{}'", command));
    }
    raw += b;
    if (b[0] == '\0') return finish_frame(command, layout, std::move(raw), deadline_s);
  }
  return finish_line(command, std::move(raw), deadline_s);
}

}  // namespace station::drivers::ascii
