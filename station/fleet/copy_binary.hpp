// COPY's binary format (postgresql.org/docs/15/sql-copy.html, "Binary Format"): the rows a
// forwarder streams in bulk (a run's 1 Hz samples), each value as the server stores it, so the
// server parses no text (issue 37: parsing the text was a fifth of the server's COPY) and the
// station formats no decimal.
#pragma once

#include <span>
#include <stdexcept>
#include <string>

#include "station/store/sqlite.hpp"

namespace station::fleet {

/// A central column's type, as its binary form is written (int8 and float8 big-endian, uuid its
/// 16 bytes, text its bytes).
enum class PgType { uuid, text, float8, int8 };

/// The central samples' column types (schemas/fleet/001_init.sql), in fleet_table("samples")'s
/// column order: the forwarder sends a run's samples in the binary format
/// (tests/fleet/test_fleet_binary_copy.cpp checks them against the server's catalog).
inline constexpr PgType kCentralSampleTypes[] = {
    PgType::uuid,   PgType::text,   PgType::float8, PgType::int8,   PgType::float8, PgType::float8,
    PgType::float8, PgType::float8, PgType::float8, PgType::float8, PgType::int8,   PgType::int8};

/// A value that cannot be written as its column's type (the COPY fails, no row is written).
struct CopyValueError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The 19 bytes that open a binary COPY: signature, flags 0, no header extension.
void append_binary_copy_header(std::string& out);
/// The trailer that ends one: a field count of -1.
void append_binary_copy_trailer(std::string& out);
/// The current row of `st` as one binary tuple, column c as `types[c]`: NULL as NULL; a float8
/// from an INTEGER or REAL value; an int8 only from an INTEGER; a uuid from its 32 hex digits
/// (dashes allowed, as PostgreSQL reads it). Anything else throws CopyValueError naming the
/// column: the COPY then fails and no row is written, as when the server refuses a text value.
void append_binary_copy_row(const Statement& st, std::span<const PgType> types,
                            std::span<const std::string_view> names, std::string& out);

}  // namespace station::fleet
