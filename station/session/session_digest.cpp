// digest.txt: SHA-256 (OpenSSL libcrypto) of each session file's decompressed bytes, its line
// count, and a 16-bit tag per line.
#include "station/session/session_digest.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <string_view>

#include "station/common/input_error.hpp"
#include "station/session/session_log.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kTagsPerRow = 64;  // tags per "tags" line of digest.txt

struct MdCtxFree {
  void operator()(EVP_MD_CTX* c) const noexcept { EVP_MD_CTX_free(c); }
};
using MdCtx = std::unique_ptr<EVP_MD_CTX, MdCtxFree>;

/// What is wrong with a file's compressed data (the digest names it at the line it reached).
struct DataError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

MdCtx sha256_ctx() {
  MdCtx c(EVP_MD_CTX_new());
  if (!c || EVP_DigestInit_ex(c.get(), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 unavailable (OpenSSL EVP)");
  return c;
}

std::array<unsigned char, EVP_MAX_MD_SIZE> finish(EVP_MD_CTX* c) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned n = 0;
  EVP_DigestFinal_ex(c, md.data(), &n);
  EVP_DigestInit_ex(c, EVP_sha256(), nullptr);  // ready for the next line
  return md;
}

/// `dir`/`name`, or `dir`/`name`.gz when only that exists (as the replay's readers resolve it).
std::string resolved(const std::string& dir, const std::string& name) {
  const fs::path plain = fs::path(dir) / name;
  if (!fs::exists(plain) && fs::exists(plain.string() + ".gz")) return plain.string() + ".gz";
  return plain.string();
}

struct InflateEnd {
  void operator()(z_stream* z) const noexcept { inflateEnd(z); }
};

/// Inflates the gzip members (RFC 1952 2.2: a file is one or more, concatenated) of `in`, whose
/// first `raw` bytes are read already, into `each`. Throws DataError for corrupt compressed data,
/// a member cut short, or bytes after the last member that begin none (zlib's gzread and gzip(1)
/// skip them: they are not the run's).
void inflate_members(std::ifstream& in, std::vector<char>& raw, std::size_t had,
                     const std::function<void(std::string_view)>& each) {
  z_stream z{};
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) throw std::runtime_error("zlib: inflateInit2");
  const std::unique_ptr<z_stream, InflateEnd> end(&z);
  std::vector<char> out(raw.size());
  std::uint64_t consumed = 0;  // bytes of the file inflate has taken
  bool in_member = true;       // bytes given to the member inflate is on
  z.next_in = reinterpret_cast<Bytef*>(raw.data());
  z.avail_in = static_cast<uInt>(had);
  while (true) {
    if (z.avail_in == 0) {
      in.read(raw.data(), static_cast<std::streamsize>(raw.size()));
      if (in.gcount() == 0) break;
      z.next_in = reinterpret_cast<Bytef*>(raw.data());
      z.avail_in = static_cast<uInt>(in.gcount());
    }
    const uInt before = z.avail_in;
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    const int rc = inflate(&z, Z_NO_FLUSH);
    each(std::string_view(out.data(), out.size() - z.avail_out));
    if (rc == Z_DATA_ERROR && !in_member)
      throw DataError(
          fmt::format("bytes after the end of the compressed data (from byte {} of "
                      "the file): not what the run wrote",
                      consumed));
    if (rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR)
      throw DataError("corrupt compressed data");
    consumed += before - z.avail_in;
    in_member = rc != Z_STREAM_END;
    if (rc == Z_STREAM_END && inflateReset(&z) != Z_OK) throw DataError("corrupt compressed data");
  }
  if (in_member) throw DataError("corrupt compressed data (cut short)");
}

/// Calls `each` with the decompressed bytes of `file`: a gzip file inflated member by member, any
/// other file as it is (as zlib's gzread reads it). Throws DataError for corrupt compressed data
/// or bytes after its end, after handing out what came before it.
void for_each_chunk(const std::string& file, const std::function<void(std::string_view)>& each) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open", file));
  std::vector<char> raw(std::size_t{1} << 16);
  in.read(raw.data(), static_cast<std::streamsize>(raw.size()));
  const auto had = static_cast<std::size_t>(in.gcount());
  if (had >= 2 && raw[0] == '\x1f' && raw[1] == '\x8b') return inflate_members(in, raw, had, each);
  for (std::size_t n = had; n > 0; n = static_cast<std::size_t>(in.gcount())) {
    each(std::string_view(raw.data(), n));
    in.read(raw.data(), static_cast<std::streamsize>(raw.size()));
  }
}

FileDigest digest_path(const std::string& file, std::string name, std::string* corrupt) {
  FileDigest d{std::move(name), 0, {}, {}};
  const MdCtx whole = sha256_ctx(), line = sha256_ctx();
  bool open_line = false;
  const auto end_line = [&] {
    const auto md = finish(line.get());
    d.tags.push_back(static_cast<std::uint16_t>(md[0] << 8 | md[1]));
    open_line = false;
  };
  const auto chunk = [&](std::string_view bytes) {
    EVP_DigestUpdate(whole.get(), bytes.data(), bytes.size());
    while (!bytes.empty()) {
      const auto nl = bytes.find('\n');
      const auto take = nl == std::string_view::npos ? bytes.size() : nl + 1;
      EVP_DigestUpdate(line.get(), bytes.data(), take);
      open_line = true;
      if (nl != std::string_view::npos) end_line();
      bytes.remove_prefix(take);
    }
  };
  try {
    for_each_chunk(file, chunk);
  } catch (const DataError& e) {
    if (corrupt == nullptr) throw InputError(fmt::format("{}: {}", file, e.what()));
    *corrupt = e.what();  // the complete lines before it are kept
    open_line = false;
  }
  if (open_line) end_line();  // a last line without its newline is a line too
  d.lines = static_cast<std::int64_t>(d.tags.size());
  const auto md = finish(whole.get());
  for (int i = 0; i < 32; ++i)
    d.sha256_hex += fmt::format("{:02x}", md[static_cast<std::size_t>(i)]);
  return d;
}

}  // namespace

std::string digest_text(const std::vector<FileDigest>& files) {
  std::string out =
      "# The digest of this session's files, written when the run ended (schemas/session.md):\n"
      "# file NAME LINES SHA-256; tags NAME FIRST_LINE TAG... (per line, 4 hex digits)\n";
  for (const auto& f : files) out += fmt::format("file {} {} {}\n", f.name, f.lines, f.sha256_hex);
  for (const auto& f : files) {
    for (std::size_t i = 0; i < f.tags.size(); i += kTagsPerRow) {
      out += fmt::format("tags {} {} ", f.name, i + 1);
      for (std::size_t k = i; k < std::min(f.tags.size(), i + kTagsPerRow); ++k)
        out += fmt::format("{:04x}", f.tags[k]);
      out += '\n';
    }
  }
  return out;
}

std::string decompressed_bytes(const std::string& file) {
  std::string out;
  try {
    for_each_chunk(file, [&out](std::string_view bytes) { out.append(bytes); });
  } catch (const DataError& e) {
    throw InputError(fmt::format("{}: {}", file, e.what()));
  }
  return out;
}

const std::vector<std::string>& digested_files() {
  // ascii.log: sessions since issue 20 (line devices); an older session has none and its digest
  // no entry for it.
  static const std::vector<std::string> files{"session.toml", "can.log",   "gpio.log",
                                              "modbus.log",   "ascii.log", "result.json"};
  return files;
}

FileDigest digest_file(const std::string& dir, const std::string& name, std::string* corrupt) {
  return digest_path(resolved(dir, name), name, corrupt);
}

void write_session_digest(const std::string& dir) {
  std::vector<FileDigest> files;
  for (const auto& name : digested_files()) {
    const auto plain = fs::path(dir) / name;
    if (name == "ascii.log" && !fs::exists(plain) && !fs::exists(plain.string() + ".gz")) continue;
    files.push_back(digest_file(dir, name));
  }
  const auto path = fs::path(dir) / "digest.txt";
  const auto tmp = fs::path(dir) / "digest.txt.tmp";
  {
    std::ofstream out(tmp);
    out << digest_text(files);
    if (!out) throw InputError(fmt::format("{}: cannot write the session digest", tmp.string()));
  }
  fs::rename(tmp, path);
}

std::string DigestMismatch::message() const {
  return line ? fmt::format("{}:{}: {}", file, *line, what) : fmt::format("{}: {}", file, what);
}

}  // namespace station
