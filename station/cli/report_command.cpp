// `station report --db DB --run ID --out DIR [--pdf]`: the run's calibration report.
#include <fmt/format.h>

#include "station/cli/commands.hpp"
#include "station/cli/exit_status.hpp"
#include "station/report/report.hpp"

namespace station {

void add_report_command(CLI::App& app, CommandStatus& status) {
  auto o = std::make_shared<report::ReportOptions>();
  auto* cmd = app.add_subcommand(
      "report",
      "Write a run's calibration report: self-contained HTML pages (the paper's figures)");
  cmd->footer(exit_status_footer({{0, "the report was written"}}));
  cmd->add_option("--db", o->db, "SQLite database (opened read-only)")->required();
  cmd->add_option("--run", o->run_id, "run id")->required();
  cmd->add_option("--out", o->out_dir, "output directory (created when missing)")->required();
  cmd->add_flag("--pdf", o->pdf, "also print each page to PDF with headless Chromium");
  cmd->add_option("--dygraphs-dir", o->dygraphs_dir,
                  "where libjs-dygraphs is installed (default /usr/share/javascript/dygraphs)");
  cmd->callback([o, &status] {
    const auto files = report::write_report(*o);
    fmt::print("{}\n", files.index);
    for (const auto& p : files.pages) fmt::print("{}\n", p);
    for (const auto& p : files.pdfs) fmt::print("{}\n", p);
    status.exit_code = 0;
  });
}

}  // namespace station
