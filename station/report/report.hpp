// `station report`: a run's calibration report as self-contained HTML files (and PDF).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace station::report {

/// What to report and where.
struct ReportOptions {
  std::string db, out_dir;
  std::int64_t run_id = 0;
  bool pdf = false;                   ///< also print each page to PDF with headless Chromium
  std::string dygraphs_dir;           ///< libjs-dygraphs' directory (empty: the Debian path)
  std::string chromium = "chromium";  ///< the browser for --pdf, looked up on PATH
};

/// The files written: the index first, then one page per serial with a fit and the acceptance
/// pages (report_acceptance.hpp), then PDFs.
struct ReportFiles {
  std::string index;
  std::vector<std::string> pages, pdfs;
};

/// Opens `db` read-only, writes run-ID.html, run-ID-slotN-SERIAL.html and run-ID-KIND.html (an
/// acceptance test's) into out_dir (created when missing). Throws InputError (no run, no fit
/// and no acceptance step, no dygraphs, no chromium) and
/// SqliteError (not a station database). Blocks while Chromium prints.
ReportFiles write_report(const ReportOptions& o);

/// A serial as a file-name part: letters, digits, '.', '-' and '_' kept, anything else '_'.
std::string file_safe(const std::string& serial);

}  // namespace station::report
