// Result type for run-time device I/O: a value or a typed error, never an exception.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace station::drivers {

/// What went wrong with one device transaction.
enum class ErrorKind {
  timeout,       ///< no (complete) answer within the transaction's deadline
  protocol,      ///< an answer that does not parse or contradicts the wire definition
  exception,     ///< the device answered with a protocol-level exception (Modbus exception code)
  disconnected,  ///< the transport is closed or was never opened
  range,         ///< a value outside what the device or map allows
  io,            ///< any other operating-system error on the transport
};

/// Human-readable name of an ErrorKind ("timeout", "protocol", ...).
constexpr const char* to_string(ErrorKind k) {
  switch (k) {
    case ErrorKind::timeout:
      return "timeout";
    case ErrorKind::protocol:
      return "protocol";
    case ErrorKind::exception:
      return "exception";
    case ErrorKind::disconnected:
      return "disconnected";
    case ErrorKind::range:
      return "range";
    case ErrorKind::io:
      return "io";
  }
  return "unknown";
}

/// A typed device error with a message naming the device and what failed.
struct Error {
  ErrorKind kind;
  std::string message;
};

/// Either a T or an Error. Cheap to move; check ok() before value().
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

/// Result of an operation with no value.
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT

  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const { return error_; }

 private:
  Error error_{ErrorKind::io, {}};
  bool ok_ = true;
};

/// Shorthand for building an Error result.
inline Error make_error(ErrorKind kind, std::string message) {
  return Error{kind, std::move(message)};
}

}  // namespace station::drivers
