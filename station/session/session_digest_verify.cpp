// Checking a session's files against its digest.txt (see session_digest.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <map>

#include "station/common/input_error.hpp"
#include "station/session/session_digest.hpp"
#include "station/session/session_log.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;

std::string_view field(std::string_view& rest) {
  const auto start = rest.find_first_not_of(' ');
  if (start == std::string_view::npos) return rest = {}, std::string_view{};
  rest.remove_prefix(start);
  const auto end = std::min(rest.find(' '), rest.size());
  const auto f = rest.substr(0, end);
  rest.remove_prefix(end);
  return f;
}

template <typename T>
bool parse_number(std::string_view s, T& v, int base = 10) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v, base);
  return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
}

/// One "tags" line's hex digits appended to `tags`; false when they are not 4-digit groups.
bool append_tags(std::string_view hex, std::vector<std::uint16_t>& tags) {
  if (hex.empty() || hex.size() % 4 != 0) return false;
  for (std::size_t i = 0; i < hex.size(); i += 4) {
    std::uint16_t t = 0;
    if (!parse_number(hex.substr(i, 4), t, 16)) return false;
    tags.push_back(t);
  }
  return true;
}

/// Per file, the digest.txt line each "tags" line is on, by the first file line it covers.
using TagLines = std::map<std::string, std::map<std::int64_t, int>>;

/// digest.txt as written: the files in order of their "file" lines. Throws InputError FILE:LINE.
std::map<std::string, FileDigest> read_digest(const std::string& path, std::string& read_as,
                                              TagLines& tag_lines) {
  std::map<std::string, FileDigest> out;
  read_as = for_each_line(path, [&](std::string_view line, int line_no) {
    if (line.front() == '#') return;
    std::string_view rest = line;
    const auto kind = field(rest), name = field(rest), number = field(rest), value = field(rest);
    const auto bad = [&](const char* what) {
      return InputError(fmt::format("{}:{}: {}", read_as.empty() ? path : read_as, line_no, what));
    };
    std::int64_t n = 0;
    if (!parse_number(number, n) || n < 0 || value.empty() || !field(rest).empty())
      throw bad("expected 'file NAME LINES SHA256' or 'tags NAME FIRST_LINE TAGS'");
    if (kind == "file") {
      if (value.size() != 64 || out.contains(std::string(name))) throw bad("bad file line");
      out[std::string(name)] = {std::string(name), n, std::string(value), {}};
    } else if (kind == "tags") {
      auto it = out.find(std::string(name));
      if (it == out.end() || static_cast<std::int64_t>(it->second.tags.size()) + 1 != n ||
          !append_tags(value, it->second.tags))
        throw bad("tags out of order or not 4-digit hex");
      tag_lines[std::string(name)][n] = line_no;
    } else {
      throw bad("unknown line kind");
    }
  });
  for (const auto& [name, d] : out)
    if (static_cast<std::int64_t>(d.tags.size()) != d.lines)
      throw InputError(
          fmt::format("{}: {} has {} lines but {} tags", read_as, name, d.lines, d.tags.size()));
  return out;
}

std::optional<DigestMismatch> compare(const std::string& file, const FileDigest& recorded,
                                      const FileDigest& actual) {
  const auto n = std::min(recorded.tags.size(), actual.tags.size());
  const auto at =
      std::mismatch(recorded.tags.begin(), recorded.tags.begin() + n, actual.tags.begin());
  if (at.first != recorded.tags.begin() + n) {
    const auto line = (at.first - recorded.tags.begin()) + 1;
    return DigestMismatch{file, line, "not the line the run wrote (digest.txt)"};
  }
  if (actual.lines > recorded.lines)
    return DigestMismatch{
        file, recorded.lines + 1,
        fmt::format("a line the run did not write (digest.txt: {} lines)", recorded.lines)};
  if (actual.lines < recorded.lines)
    return DigestMismatch{file, actual.lines + 1,
                          fmt::format("missing: the run wrote {} lines, the file has {}",
                                      recorded.lines, actual.lines)};
  if (actual.sha256_hex != recorded.sha256_hex)
    return DigestMismatch{file, std::nullopt,
                          "its SHA-256 is not the one the run wrote (digest.txt); every line's "
                          "tag matches, so the line is not known"};
  return std::nullopt;
}

/// digest.txt in its one form (digest_text of what it says, the files in digested_files()'s
/// order, hex in lower case): any other byte (a space, a comment, a case, a CR, an empty line,
/// an unknown file) is named at its line, so that no edit of the digest replays silently.
std::optional<DigestMismatch> not_canonical(const std::string& read_as,
                                            const std::map<std::string, FileDigest>& recorded) {
  std::vector<FileDigest> files;
  for (const auto& name : digested_files()) {
    if (const auto it = recorded.find(name); it != recorded.end()) files.push_back(it->second);
  }
  for (auto& f : files)
    std::transform(f.sha256_hex.begin(), f.sha256_hex.end(), f.sha256_hex.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string have;
  try {
    have = decompressed_bytes(read_as);
  } catch (const InputError& e) {  // bytes after its compressed end: "FILE: what"
    const std::string_view what(e.what());
    return DigestMismatch{read_as, std::nullopt,
                          std::string(what.substr(std::min(what.size(), read_as.size() + 2)))};
  }
  const std::string want = digest_text(files);
  if (want == have) return std::nullopt;
  const auto at = std::mismatch(want.begin(), want.end(), have.begin(), have.end());
  const auto line = 1 + std::count(have.begin(), at.second, '\n');
  return DigestMismatch{read_as, line,
                        "not as the station writes digest.txt (its one form: schemas/session.md); "
                        "an edited digest proves nothing"};
}

}  // namespace

std::optional<DigestMismatch> verify_session_digest(const std::string& dir) {
  const std::string path = (fs::path(dir) / "digest.txt").string();
  if (!fs::exists(path) && !fs::exists(path + ".gz"))
    return DigestMismatch{path, std::nullopt,
                          "missing: nothing proves the logs are the ones the run wrote"};
  std::string read_as;
  TagLines tag_lines;
  const auto recorded = read_digest(path, read_as, tag_lines);
  if (auto m = not_canonical(read_as, recorded)) return m;
  for (const auto& name : digested_files()) {
    const auto it = recorded.find(name);
    const fs::path maybe = fs::path(dir) / name;
    if (it == recorded.end() && name == "ascii.log" && !fs::exists(maybe) &&
        !fs::exists(maybe.string() + ".gz"))
      continue;  // a session from before issue 20: no line devices, no ascii.log
    if (it == recorded.end())
      return DigestMismatch{read_as, std::nullopt, fmt::format("no entry for {}", name)};
    const fs::path plain = fs::path(dir) / name;
    if (!fs::exists(plain) && !fs::exists(plain.string() + ".gz"))
      return DigestMismatch{plain.string(), std::nullopt, "missing (digest.txt lists it)"};
    const std::string file =
        fs::exists(plain) ? plain.string() : plain.string() + ".gz";  // as the readers take it
    std::string corrupt;
    const FileDigest actual = digest_file(dir, name, &corrupt);
    if (auto m = compare(file, it->second, actual);
        m && (corrupt.empty() || m->line <= actual.lines)) {
      if (actual.sha256_hex != it->second.sha256_hex || !m->line) return m;
      // The file is byte for byte the one whose SHA-256 the digest holds: the tag is what changed.
      const auto& lines = tag_lines[name];
      const int at = std::prev(lines.upper_bound(*m->line))->second;
      return DigestMismatch{read_as, at,
                            fmt::format("the tag of {} line {} is not the one of the bytes its "
                                        "SHA-256 proves",
                                        name, *m->line)};
    }
    if (!corrupt.empty()) return DigestMismatch{file, actual.lines + 1, corrupt};
  }
  return std::nullopt;
}

}  // namespace station
