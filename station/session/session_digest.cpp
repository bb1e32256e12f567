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
#include <utility>

#include "station/common/input_error.hpp"
#include "station/session/session_files.hpp"
#include "station/session/session_log.hpp"

namespace station {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kTagsPerRow = 64;  // tags per "tags" line of digest.txt

struct MdCtxFree {
  void operator()(EVP_MD_CTX* c) const noexcept { EVP_MD_CTX_free(c); }
};
using MdCtx = std::unique_ptr<EVP_MD_CTX, MdCtxFree>;

MdCtx sha256_ctx() {
  MdCtx c(EVP_MD_CTX_new());
  if (!c || EVP_DigestInit_ex(c.get(), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 unavailable (OpenSSL EVP)");
  return c;
}

std::array<unsigned char, EVP_MAX_MD_SIZE> finish_md(EVP_MD_CTX* c) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned n = 0;
  EVP_DigestFinal_ex(c, md.data(), &n);
  // Ready for the next line with the digest it holds: EVP_DigestInit_ex(c, EVP_sha256()) would
  // fetch SHA-256 from the provider again, under a lock, for each of a session's ~2.6 M lines
  // (perf: 13 % of a long replay).
  EVP_DigestInit_ex2(c, nullptr, nullptr);
  return md;
}

/// `dir`/`name`, or `dir`/`name`.gz when only that exists (session_file: the replay's readers'
/// one rule; both refused).
std::string resolved(const std::string& dir, const std::string& name) {
  return session_file((fs::path(dir) / name).string());
}

/// Calls `each` with the decompressed bytes of `file` (DecompressedReader). Throws
/// CompressedDataError after handing out what came before it.
void for_each_chunk(const std::string& file, const std::function<void(std::string_view)>& each) {
  DecompressedReader in(file);
  for (auto bytes = in.next(); !bytes.empty(); bytes = in.next()) each(bytes);
}

FileDigest digest_path(const std::string& file, std::string name, std::string* corrupt) {
  DigestBuilder d(std::move(name));
  try {
    for_each_chunk(file, [&d](std::string_view bytes) { d.add(bytes); });
  } catch (const CompressedDataError& e) {
    if (corrupt == nullptr) throw InputError(fmt::format("{}: {}", file, e.what()));
    d.corrupt(e.what());
    *corrupt = e.what();  // the complete lines before it are kept
  }
  return d.finish();
}

/// `tag` as 4 lower-case hex digits (fmt's "{:04x}", without a format call per tag: a long
/// session's digest has millions).
void append_hex4(std::string& out, std::uint16_t tag) {
  static constexpr char kHex[] = "0123456789abcdef";
  for (int shift = 12; shift >= 0; shift -= 4) out += kHex[(tag >> shift) & 0xf];
}

}  // namespace

struct DecompressedReader::Inflater {
  z_stream z{};
  Inflater() {
    if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) throw std::runtime_error("zlib: inflateInit2");
  }
  ~Inflater() { inflateEnd(&z); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;
};

DecompressedReader::DecompressedReader(const std::string& file)
    : in_(file, std::ios::binary), raw_(std::size_t{1} << 16) {
  if (!in_) throw InputError(fmt::format("{}: cannot open", file));
  in_.read(raw_.data(), static_cast<std::streamsize>(raw_.size()));
  first_ = static_cast<std::size_t>(in_.gcount());
  if (first_ < 2 || raw_[0] != '\x1f' || raw_[1] != '\x8b') return;
  z_ = std::make_unique<Inflater>();
  out_.resize(raw_.size());
  z_->z.next_in = reinterpret_cast<Bytef*>(raw_.data());
  z_->z.avail_in = static_cast<uInt>(first_);
  first_ = 0;
}

DecompressedReader::~DecompressedReader() = default;

std::string_view DecompressedReader::next() {
  if (!pending_.empty()) throw CompressedDataError(std::exchange(pending_, {}));
  if (!z_) {  // a plain file as it is
    if (first_ == 0) {
      in_.read(raw_.data(), static_cast<std::streamsize>(raw_.size()));
      first_ = static_cast<std::size_t>(in_.gcount());
    }
    return {raw_.data(), std::exchange(first_, 0)};
  }
  z_stream& z = z_->z;
  while (true) {
    if (z.avail_in == 0) {
      in_.read(raw_.data(), static_cast<std::streamsize>(raw_.size()));
      if (in_.gcount() == 0) {
        if (in_member_) throw CompressedDataError("corrupt compressed data (cut short)");
        return {};
      }
      z.next_in = reinterpret_cast<Bytef*>(raw_.data());
      z.avail_in = static_cast<uInt>(in_.gcount());
    }
    const uInt before = z.avail_in;
    z.next_out = reinterpret_cast<Bytef*>(out_.data());
    z.avail_out = static_cast<uInt>(out_.size());
    const int rc = inflate(&z, Z_NO_FLUSH);
    const std::string_view bytes(out_.data(), out_.size() - z.avail_out);
    if (rc == Z_DATA_ERROR && !in_member_)
      pending_ = fmt::format(
          "bytes after the end of the compressed data (from byte {} of the file): not what the "
          "run wrote",
          consumed_);
    else if (rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR)
      pending_ = "corrupt compressed data";
    else if (rc == Z_STREAM_END && inflateReset(&z) != Z_OK)
      pending_ = "corrupt compressed data";
    if (pending_.empty()) {
      consumed_ += before - z.avail_in;
      in_member_ = rc != Z_STREAM_END;
    }
    if (!bytes.empty()) return bytes;
    if (!pending_.empty()) throw CompressedDataError(std::exchange(pending_, {}));
  }
}

struct DigestBuilder::Ctx {
  MdCtx whole = sha256_ctx(), line = sha256_ctx();
};

DigestBuilder::DigestBuilder(std::string name) : ctx_(std::make_unique<Ctx>()) {
  d_.name = std::move(name);
}

DigestBuilder::~DigestBuilder() = default;

void DigestBuilder::add(std::string_view bytes) {
  EVP_DigestUpdate(ctx_->whole.get(), bytes.data(), bytes.size());
  while (!bytes.empty()) {
    const auto nl = bytes.find('\n');
    const auto take = nl == std::string_view::npos ? bytes.size() : nl + 1;
    EVP_DigestUpdate(ctx_->line.get(), bytes.data(), take);
    open_line_ = true;
    if (nl != std::string_view::npos) end_line();
    bytes.remove_prefix(take);
  }
}

void DigestBuilder::end_line() {
  const auto md = finish_md(ctx_->line.get());
  d_.tags.push_back(static_cast<std::uint16_t>(md[0] << 8 | md[1]));
  open_line_ = false;
}

void DigestBuilder::corrupt(std::string what) {
  corrupt_ = std::move(what);
  open_line_ = false;
}

FileDigest DigestBuilder::finish() {
  if (open_line_) end_line();  // a last line without its newline is a line too
  d_.lines = static_cast<std::int64_t>(d_.tags.size());
  const auto md = finish_md(ctx_->whole.get());
  for (int i = 0; i < 32; ++i)
    d_.sha256_hex += fmt::format("{:02x}", md[static_cast<std::size_t>(i)]);
  return std::move(d_);
}

std::string digest_text(const std::vector<FileDigest>& files) {
  std::string out =
      "# The digest of this session's files, written when the run ended (schemas/session.md):\n"
      "# file NAME LINES SHA-256; tags NAME FIRST_LINE TAG... (per line, 4 hex digits)\n";
  for (const auto& f : files) out += fmt::format("file {} {} {}\n", f.name, f.lines, f.sha256_hex);
  for (const auto& f : files) {
    for (std::size_t i = 0; i < f.tags.size(); i += kTagsPerRow) {
      out += fmt::format("tags {} {} ", f.name, i + 1);
      for (std::size_t k = i; k < std::min(f.tags.size(), i + kTagsPerRow); ++k)
        append_hex4(out, f.tags[k]);
      out += '\n';
    }
  }
  return out;
}

std::string decompressed_bytes(const std::string& file) {
  std::string out;
  try {
    for_each_chunk(file, [&out](std::string_view bytes) { out.append(bytes); });
  } catch (const CompressedDataError& e) {
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
