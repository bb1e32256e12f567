// Checking a session's files against its digest.txt (see session_digest.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <map>
#include <memory>
#include <string_view>

#include "station/common/input_error.hpp"
#include "station/session/session_digest.hpp"
#include "station/session/session_files.hpp"
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

/// digest.txt as written (`text`, its bytes as read from `read_as`): the files in order of their
/// "file" lines. Lines as LogLineReader gives them (a CR before the newline and empty lines left
/// out): not_canonical names what that forgives. Throws InputError FILE:LINE.
std::map<std::string, FileDigest> read_digest(const std::string& read_as, std::string_view text,
                                              TagLines& tag_lines) {
  std::map<std::string, FileDigest> out;
  std::map<std::string, int> file_line;  // the line of each file's `file` entry
  int line_no = 0;
  for (std::size_t begin = 0; begin < text.size();) {
    const auto nl = std::min(text.find('\n', begin), text.size());
    std::string_view line = text.substr(begin, nl - begin);
    begin = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty() || line.front() == '#') continue;
    std::string_view rest = line;
    const auto kind = field(rest), name = field(rest), number = field(rest), value = field(rest);
    const auto bad = [&](const char* what) {
      return InputError(fmt::format("{}:{}: {}", read_as, line_no, what));
    };
    std::int64_t n = 0;
    if (!parse_number(number, n) || n < 0 || value.empty() || !field(rest).empty())
      throw bad("expected 'file NAME LINES SHA256' or 'tags NAME FIRST_LINE TAGS'");
    if (kind == "file") {
      if (value.size() != 64 || out.contains(std::string(name))) throw bad("bad file line");
      out[std::string(name)] = {std::string(name), n, std::string(value), {}};
      file_line[std::string(name)] = line_no;
    } else if (kind == "tags") {
      auto it = out.find(std::string(name));
      if (it == out.end())  // its `file` line deleted: the file is what is missing
        throw bad(fmt::format("tags of {0} with no 'file {0} LINES SHA256' line before them: the "
                              "digest's entry for {0} is missing",
                              name)
                      .c_str());
      if (static_cast<std::int64_t>(it->second.tags.size()) + 1 != n ||
          !append_tags(value, it->second.tags))
        throw bad("tags out of order or not 4-digit hex");
      tag_lines[std::string(name)][n] = line_no;
    } else {
      throw bad("unknown line kind");
    }
  }
  // The count on a `file` line and its tags lines disagree: the file line is named (its count
  // is the one field the tags do not spell out).
  for (const auto& [name, d] : out)
    if (static_cast<std::int64_t>(d.tags.size()) != d.lines)
      throw InputError(fmt::format("{}:{}: {} has {} lines but {} tags", read_as, file_line[name],
                                   name, d.lines, d.tags.size()));
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
std::optional<DigestMismatch> not_canonical(const std::string& read_as, const std::string& have,
                                            const std::map<std::string, FileDigest>& recorded) {
  std::vector<FileDigest> files;
  for (const auto& name : digested_files()) {
    if (const auto it = recorded.find(name); it != recorded.end()) files.push_back(it->second);
  }
  for (auto& f : files)
    std::transform(f.sha256_hex.begin(), f.sha256_hex.end(), f.sha256_hex.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string want = digest_text(files);
  if (want == have) return std::nullopt;
  const auto at = std::mismatch(want.begin(), want.end(), have.begin(), have.end());
  const auto line = 1 + std::count(have.begin(), at.second, '\n');
  return DigestMismatch{read_as, line,
                        "not as the station writes digest.txt (its one form: schemas/session.md); "
                        "an edited digest proves nothing"};
}

/// `file` (digest.txt calls it `name`) against what digest.txt says: the first line that is not
/// the run's, or nothing. `corrupt`: what stopped the read early, if anything.
std::optional<DigestMismatch> file_mismatch(const std::string& file, const std::string& name,
                                            const FileDigest& recorded, const FileDigest& actual,
                                            const std::string& corrupt, const std::string& read_as,
                                            const TagLines& tag_lines) {
  if (auto m = compare(file, recorded, actual); m && (corrupt.empty() || m->line <= actual.lines)) {
    if (actual.sha256_hex != recorded.sha256_hex || !m->line) return m;
    // The file is byte for byte the one whose SHA-256 the digest holds: the tag is what changed.
    const auto lines = tag_lines.find(name);
    if (lines == tag_lines.end()) return m;
    const int at = std::prev(lines->second.upper_bound(*m->line))->second;
    return DigestMismatch{read_as, at,
                          fmt::format("the tag of {} line {} is not the one of the bytes its "
                                      "SHA-256 proves",
                                      name, *m->line)};
  }
  if (!corrupt.empty()) return DigestMismatch{file, actual.lines + 1, corrupt};
  return std::nullopt;
}

}  // namespace

struct SessionReads::Recorded {
  std::string read_as;  // digest.txt as read (or digest.txt.gz)
  std::map<std::string, FileDigest> files;
  TagLines tag_lines;
};

SessionReads::SessionReads(std::string dir, bool verify) : dir_(std::move(dir)) {
  // A file there plain and as .gz is refused before anything is read (session_file).
  for (const auto& name : digested_files()) (void)session_file((fs::path(dir_) / name).string());
  (void)session_file((fs::path(dir_) / "digest.txt").string());
  if (verify) recorded_ = std::make_unique<Recorded>();
}

SessionReads::~SessionReads() = default;

LogLineReader& SessionReads::reader(const std::string& name) {
  for (auto& [n, r] : readers_)
    if (n == name) return *r;
  auto r = std::make_unique<LogLineReader>((fs::path(dir_) / name).string());
  if (recorded_ && recorded_->files.contains(name)) {
    digests_.emplace_back(name, std::make_unique<DigestBuilder>(name));
    r->digest_into(digests_.back().second.get());
  }
  readers_.emplace_back(name, std::move(r));
  return *readers_.back().second;
}

std::optional<DigestMismatch> SessionReads::check_up_front() {
  if (!recorded_) return std::nullopt;
  const std::string path = (fs::path(dir_) / "digest.txt").string();
  if (!session_file_exists(path))
    return DigestMismatch{path, std::nullopt,
                          "missing: nothing proves the logs are the ones the run wrote"};
  auto& rec = *recorded_;
  rec.read_as = session_file(path);
  std::string have;
  std::optional<std::string> after_end;  // bytes after its compressed end: "FILE: what"
  try {
    have = decompressed_bytes(rec.read_as);
  } catch (const InputError& e) {
    // Bytes after its compressed end are a mismatch (below); corrupt data is no digest at all.
    const std::string_view what(e.what());
    if (what.find("after the end") == std::string_view::npos) throw;
    after_end = what.substr(std::min(what.size(), rec.read_as.size() + 2));
  }
  rec.files = read_digest(rec.read_as, have, rec.tag_lines);
  if (after_end) return DigestMismatch{rec.read_as, std::nullopt, *after_end};
  // A file there without its entry (its `file` line deleted, a file of no lines has no tags):
  // named, not the line that now stands where its entry was.
  for (const auto& name : digested_files())
    if (!rec.files.contains(name) && session_file_exists((fs::path(dir_) / name).string()))
      return DigestMismatch{rec.read_as, std::nullopt,
                            fmt::format("no 'file {}' line: the digest's entry for {} is "
                                        "missing, the file is there",
                                        name, name)};
  if (auto m = not_canonical(rec.read_as, have, rec.files)) return m;
  return check_file(digested_files().front());  // session.toml: read for its meaning first
}

std::optional<DigestMismatch> SessionReads::check_file(const std::string& name) {
  const auto& rec = *recorded_;
  const auto it = rec.files.find(name);
  const fs::path plain = fs::path(dir_) / name;
  const bool exists = fs::exists(plain) || fs::exists(plain.string() + ".gz");
  if (it == rec.files.end() && name == "ascii.log" && !exists)
    return std::nullopt;  // a session from before issue 20: no line devices, no ascii.log
  if (it == rec.files.end())
    return DigestMismatch{rec.read_as, std::nullopt, fmt::format("no entry for {}", name)};
  if (!exists) return DigestMismatch{plain.string(), std::nullopt, "missing (digest.txt lists it)"};
  // What the replay did not read of the file, read now: the digest takes every byte.
  LogLineReader& r = reader(name);
  std::string_view line;
  int line_no = 0;
  try {
    while (r.next(line, line_no)) {
    }
  } catch (const InputError&) {  // corrupt compressed data: the digest was told
  }
  DigestBuilder* d = nullptr;
  for (auto& [n, b] : digests_)
    if (n == name) d = b.get();
  std::string corrupt;
  if (d == nullptr) {  // opened before digest.txt was read: digested on its own
    const FileDigest actual = digest_file(dir_, name, &corrupt);
    return file_mismatch(r.file(), name, it->second, actual, corrupt, rec.read_as, rec.tag_lines);
  }
  corrupt = d->corrupt_what();
  return file_mismatch(r.file(), name, it->second, d->finish(), corrupt, rec.read_as,
                       rec.tag_lines);
}

std::optional<DigestMismatch> SessionReads::check_rest() {
  if (!recorded_) return std::nullopt;
  for (std::size_t i = 1; i < digested_files().size(); ++i)
    if (auto m = check_file(digested_files()[i])) return m;
  return std::nullopt;
}

std::optional<DigestMismatch> verify_session_digest(const std::string& dir) {
  SessionReads reads(dir, true);
  if (auto m = reads.check_up_front()) return m;
  return reads.check_rest();
}

}  // namespace station
