// The one exception type for bad user input (CSV, config, protocol files): its message names
// the file, the line and the key or column. main() turns it into one line and exit status 2.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace station {

/// Bad user input; what() reads "FILE:LINE: key 'a.b': what is wrong". Always one line: control
/// characters a message quotes from the input (a key with a newline, a parser's "saw '...'")
/// are escaped as \n, \r, \t or \xNN.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(one_line(what)) {}

  /// Several problems found at once (e.g. every unreachable device): one line each.
  static InputError lines(const std::vector<std::string>& problems) {
    std::string joined;
    for (const auto& p : problems) joined += (joined.empty() ? "" : "\n") + one_line(p);
    return InputError(joined, Verbatim{});
  }

  /// `s` with every control character escaped.
  static std::string one_line(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (const char c : s) {
      const auto u = static_cast<unsigned char>(c);
      if (c == '\n') {
        out += "\\n";
      } else if (c == '\r') {
        out += "\\r";
      } else if (c == '\t') {
        out += "\\t";
      } else if (u < 0x20 || u == 0x7f) {
        char buf[5];
        std::snprintf(buf, sizeof buf, "\\x%02x", u);
        out += buf;
      } else {
        out += c;
      }
    }
    return out;
  }

 private:
  struct Verbatim {};
  InputError(const std::string& joined, Verbatim) : std::runtime_error(joined) {}
};

}  // namespace station
