// The session's digest (digest.txt, schemas/session.md "Digest"): written when the run ends, it
// proves that the files a replay reads are the ones the run wrote. Per file the SHA-256 and the
// line count of its bytes (decompressed: a gzip'd log verifies as the plain one), and per line a
// 16-bit tag (the first two bytes of the line's SHA-256) so that a changed byte is named by its
// line.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
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

/// Checks every file of `dir` against `dir`/digest.txt (or digest.txt.gz). A missing digest, a
/// missing file or a changed byte is a mismatch; a digest.txt that is not in its format throws
/// InputError naming its line.
std::optional<DigestMismatch> verify_session_digest(const std::string& dir);

}  // namespace station
