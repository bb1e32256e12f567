#include "station/fleet/copy_binary.hpp"

#include <fmt/format.h>
#include <sqlite3.h>

#include <bit>
#include <cstdint>
#include <stdexcept>

namespace station::fleet {
namespace {

template <typename T>
void put_big_endian(std::string& out, T v) {
  static_assert(std::is_unsigned_v<T>);
  for (int shift = 8 * (static_cast<int>(sizeof(T)) - 1); shift >= 0; shift -= 8)
    out.push_back(static_cast<char>((v >> shift) & 0xFF));
}

void put_length(std::string& out, std::int32_t n) {
  put_big_endian(out, static_cast<std::uint32_t>(n));
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

void put_uuid(std::string& out, std::string_view text, std::string_view column) {
  std::string bytes;
  int digits = 0, high = 0;
  for (const char c : text) {
    if (c == '-') continue;
    const int d = hex_digit(c);
    if (d < 0 || ++digits > 32)
      throw CopyValueError(fmt::format("{}: '{}' is not a uuid", column, text));
    if (digits % 2 == 1)
      high = d;
    else
      bytes.push_back(static_cast<char>(high * 16 + d));
  }
  if (digits != 32) throw CopyValueError(fmt::format("{}: '{}' is not a uuid", column, text));
  put_length(out, 16);
  out += bytes;
}

}  // namespace

void append_binary_copy_header(std::string& out) {
  out.append("PGCOPY\n\377\r\n\0", 11);
  put_length(out, 0);  // flags: no OIDs
  put_length(out, 0);  // header extension: none
}

void append_binary_copy_trailer(std::string& out) {
  put_big_endian(out, static_cast<std::uint16_t>(0xFFFF));
}

void append_binary_copy_row(const Statement& st, std::span<const PgType> types,
                            std::span<const std::string_view> names, std::string& out) {
  if (types.size() != names.size() || st.column_count() != static_cast<int>(types.size()))
    throw std::logic_error(fmt::format("a binary COPY of {} columns given {} types, {} names",
                                       st.column_count(), types.size(), names.size()));
  put_big_endian(out, static_cast<std::uint16_t>(types.size()));
  for (std::size_t i = 0; i < types.size(); ++i) {
    const int c = static_cast<int>(i);
    const int type = st.column_type(c);
    if (type == SQLITE_NULL) {
      put_length(out, -1);
      continue;
    }
    switch (types[i]) {
      case PgType::float8:
        if (type != SQLITE_FLOAT && type != SQLITE_INTEGER)
          throw CopyValueError(fmt::format("{}: not a number", names[i]));
        put_length(out, 8);
        put_big_endian(out, std::bit_cast<std::uint64_t>(st.column_double(c)));
        break;
      case PgType::int8:
        if (type != SQLITE_INTEGER)
          throw CopyValueError(
              fmt::format("{}: {} is not an integer", names[i], st.column_text(c)));
        put_length(out, 8);
        put_big_endian(out, static_cast<std::uint64_t>(st.column_int(c)));
        break;
      case PgType::uuid:
        put_uuid(out, st.column_text(c), names[i]);
        break;
      case PgType::text: {
        const std::string text = st.column_text(c);
        put_length(out, static_cast<std::int32_t>(text.size()));
        out += text;
      }
    }
  }
}

}  // namespace station::fleet
