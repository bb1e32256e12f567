// The session's digest (digest.txt, schemas/session.md "Digest"): written when the run ends, it
// proves that the files a replay reads are the ones the run wrote. Per file the SHA-256 and the
// line count of its bytes (decompressed: a gzip'd log verifies as the plain one), and per line a
// 16-bit tag (the first two bytes of the line's SHA-256) so that a changed byte is named by its
// line.
#pragma once

#include <cstdint>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace station {

/// The files digest.txt covers, in the order it lists them.
const std::vector<std::string>& digested_files();

/// What one file's bytes were.
struct FileDigest {
  std::string name;  ///< as listed (e.g. "modbus.log"; read as modbus.log.gz when only that exists)
  std::int64_t lines = 0;           ///< lines, a last line without a newline included
  std::string sha256_hex;           ///< of all the bytes
  std::vector<std::uint16_t> tags;  ///< per line (newline included), first 2 bytes of its SHA-256
};

/// Corrupt compressed data, or bytes after the end of a file's last gzip member.
struct CompressedDataError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The decompressed bytes of a file a chunk at a time: gzip members inflated (RFC 1952 2.2: one
/// or more, concatenated), any other file as it is (as zlib's gzread reads it).
class DecompressedReader {
 public:
  /// Throws InputError "FILE: cannot open".
  explicit DecompressedReader(const std::string& file);
  ~DecompressedReader();
  /// The next bytes (valid until the next call); empty at the end. Throws CompressedDataError for
  /// corrupt compressed data, a member cut short, or bytes after the last member that begin none
  /// (gzip(1) skips them: they are not the run's), after handing out what came before it.
  std::string_view next();

 private:
  struct Inflater;
  std::ifstream in_;
  std::vector<char> raw_, out_;
  std::unique_ptr<Inflater> z_;  // null: a plain file
  std::size_t first_ = 0;        // raw bytes read to tell gzip from plain, not yet handed out
  std::string pending_;          // an error found after the bytes handed out with it
  bool in_member_ = true;        // bytes given to the member inflate is on
  std::uint64_t consumed_ = 0;   // bytes of the file inflate has taken
};

/// A file's digest built from its bytes in order, as they are read (what digest_file computes).
class DigestBuilder {
 public:
  explicit DigestBuilder(std::string name);
  ~DigestBuilder();
  void add(std::string_view bytes);
  /// The bytes stopped at corrupt data (`what`): the lines before it are kept, an open one not.
  void corrupt(std::string what);
  /// What corrupt() was told ("" when nothing).
  const std::string& corrupt_what() const { return corrupt_; }
  /// The digest of what was added (a last line without its newline counted). Once.
  FileDigest finish();

 private:
  void end_line();
  struct Ctx;
  FileDigest d_;
  std::unique_ptr<Ctx> ctx_;
  bool open_line_ = false;
  std::string corrupt_;
};

/// Digests `dir`/`name` (or its .gz). Throws InputError naming the file when it cannot be read;
/// with `corrupt`, corrupt compressed data ends the digest there and says so in *corrupt.
FileDigest digest_file(const std::string& dir, const std::string& name,
                       std::string* corrupt = nullptr);

/// digest.txt's one form for `files` (schemas/session.md, "digest.txt"): two comment lines, a
/// "file" line per file, then its "tags" lines of 64 tags, fields separated by one space,
/// lower-case hex, LF line ends, nothing else. What write_session_digest writes and the only
/// text verify_session_digest accepts.
std::string digest_text(const std::vector<FileDigest>& files);

/// All the decompressed bytes of `file` (gzip members inflated, any other file as it is). Throws
/// InputError naming it for corrupt compressed data or bytes after the end of its last member.
std::string decompressed_bytes(const std::string& file);

/// Writes `dir`/digest.txt for every file of digested_files() as it is now (replacing it).
/// Throws InputError naming the path.
void write_session_digest(const std::string& dir);

/// The first file (and line, where one is known) that is not as the digest says.
struct DigestMismatch {
  std::string file;                  ///< the file read (e.g. "…/modbus.log.gz")
  std::optional<std::int64_t> line;  ///< 1-based
  std::string what;

  /// "FILE:LINE: what" or "FILE: what".
  std::string message() const;
};

class LogLineReader;

/// A session directory's files, each read once from its start by the one reader the replay asks
/// for (reader()), and checked against digest.txt as it is read: verify_session_digest's checks
/// without a read of their own. Up front digest.txt and session.toml; the rest when the replay is
/// done (check_rest), each file read on to its end first.
class SessionReads {
 public:
  /// `verify`: check against digest.txt (else only readers).
  SessionReads(std::string dir, bool verify);
  ~SessionReads();
  SessionReads(const SessionReads&) = delete;
  SessionReads& operator=(const SessionReads&) = delete;
  /// digest.txt (missing, not in its one form; throws InputError naming its line when it is not
  /// digest.txt at all) and session.toml: the first mismatch, if any.
  std::optional<DigestMismatch> check_up_front();
  /// The reader of `name` (`dir`/name, or name.gz), opened on the first call, whose bytes the
  /// digest takes as it reads them. Throws InputError when it cannot be opened.
  LogLineReader& reader(const std::string& name);
  /// Every other digested file read to its end and compared with digest.txt, in its order: the
  /// first mismatch, if any.
  std::optional<DigestMismatch> check_rest();

 private:
  std::optional<DigestMismatch> check_file(const std::string& name);
  struct Recorded;
  std::string dir_;
  std::unique_ptr<Recorded> recorded_;  // null: not verifying
  std::vector<std::pair<std::string, std::unique_ptr<LogLineReader>>> readers_;
  std::vector<std::pair<std::string, std::unique_ptr<DigestBuilder>>> digests_;
};

/// Checks every file of `dir` against `dir`/digest.txt (or digest.txt.gz). A missing digest, a
/// missing file or a changed byte is a mismatch; a digest.txt that is not in its format throws
/// InputError naming its line.
std::optional<DigestMismatch> verify_session_digest(const std::string& dir);

}  // namespace station
