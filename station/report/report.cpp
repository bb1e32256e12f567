// Writing a run's report: load, prepare, write the pages, optionally print them with Chromium.
#include "station/report/report.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "station/common/input_error.hpp"
#include "station/report/report_html.hpp"
#include "station/report/report_load.hpp"
#include "station/report/report_page.hpp"
#include "station/store/store.hpp"

extern char** environ;

namespace station::report {

namespace fs = std::filesystem;
namespace {

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw InputError(fmt::format("{}: cannot write", path.string()));
}

/// `name` on PATH (or `name` itself when it holds a '/'); empty when not found.
std::string find_program(const std::string& name) {
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : "";
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  for (std::size_t start = 0; start <= dirs.size();) {
    const auto end = std::min(dirs.find(':', start), dirs.size());
    const std::string candidate = dirs.substr(start, end - start) + "/" + name;
    if (end > start && access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return "";
}

/// Prints `html` to `pdf` with headless Chromium (argv, no shell: paths are not interpreted).
/// file:// URL of an absolute path, every byte outside RFC 3986's unreserved set and '/'
/// percent-encoded ('#', '%', '?' in a directory name would otherwise end the path).
std::string file_url(const fs::path& path) {
  std::string url = "file://";
  for (const unsigned char c : path.string()) {
    const bool keep = std::isalnum(c) || c == '/' || c == '-' || c == '.' || c == '_' || c == '~';
    url += keep ? std::string(1, static_cast<char>(c)) : fmt::format("%{:02X}", c);
  }
  return url;
}

void print_pdf(const std::string& chromium, const fs::path& html, const fs::path& pdf) {
  fs::remove(pdf);  // a PDF left from an earlier report must not pass for this one
  std::vector<std::string> args{chromium,
                                "--headless",
                                "--no-sandbox",
                                "--disable-gpu",
                                "--no-pdf-header-footer",
                                "--virtual-time-budget=10000",
                                "--print-to-pdf=" + pdf.string(),
                                file_url(fs::absolute(html))};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);  // Chromium's chatter
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, chromium.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  int status = 0;
  if (rc != 0 || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
      !fs::exists(pdf))
    throw std::runtime_error(fmt::format("{}: printing {} to PDF failed", chromium, html.string()));
}

}  // namespace

std::string file_safe(const std::string& serial) {
  std::string out;
  for (const char c : serial) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '-' || c == '_';
    out += keep ? c : '_';
  }
  // A file name is at most 255 bytes: a long serial keeps its first 80 characters (the page
  // names its slot too, so two such serials still get two files).
  if (out.size() > 80) out.resize(80);
  return out;
}

ReportFiles write_report(const ReportOptions& o) {
  const Assets assets =
      read_dygraphs(o.dygraphs_dir.empty() ? std::string(kDygraphsDir) : o.dygraphs_dir);
  const std::string chromium = o.pdf ? find_program(o.chromium) : "";
  if (o.pdf && chromium.empty())
    throw InputError(fmt::format(
        "{}: not found on PATH; --pdf prints with headless Chromium (Debian package chromium)",
        o.chromium));
  Store store(o.db, OpenMode::read_only);
  const RunReport r = load_report(store, o.run_id);
  store.db().check_unchanged();
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  if (ec || !fs::is_directory(o.out_dir))
    throw InputError(fmt::format("--out {}: cannot create the directory: {}", o.out_dir,
                                 ec ? ec.message() : "it is not a directory"));
  const fs::path dir(o.out_dir);
  ReportFiles files;
  std::vector<std::string> names;
  for (const auto& s : r.serials) {
    names.push_back(!s.fit ? "" : serial_page_name(r.run.id, s.slot.slot, s.slot.serial));
    if (names.back().empty()) continue;
    write_file(dir / names.back(), serial_html(r, s, assets));
    files.pages.push_back((dir / names.back()).string());
  }
  for (const auto p : acceptance_pages(r.acceptance)) {
    const auto path = dir / acceptance_page_name(r.run.id, p);
    write_file(path, acceptance_html(r, p, assets));
    files.pages.push_back(path.string());
  }
  files.index = (dir / index_page_name(r.run.id)).string();
  write_file(files.index, index_html(r, assets, names));
  if (o.pdf) {
    std::vector<std::string> all{files.index};
    all.insert(all.end(), files.pages.begin(), files.pages.end());
    for (const auto& html : all) {
      const auto pdf = fs::path(html).replace_extension(".pdf");
      print_pdf(chromium, html, pdf);
      files.pdfs.push_back(pdf.string());
    }
  }
  return files;
}

}  // namespace station::report
