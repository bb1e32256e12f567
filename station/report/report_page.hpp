// A page of a run's report by its file name, rendered from the store: what `station report`
// writes to files, served by the HTTP service (GET /reports/NAME, schemas/api.md) so the live
// page links a finished run's report.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "station/store/store.hpp"

namespace station::report {

/// The file name of run `run_id`'s index page: run-ID.html.
std::string index_page_name(std::int64_t run_id);
/// The file name of a serial's page: run-ID-slotN-SERIAL.html (SERIAL through file_safe).
std::string serial_page_name(std::int64_t run_id, int slot, const std::string& serial);

/// (An acceptance page's name: report_acceptance.hpp, acceptance_page_name.)
/// The page named `name` (as write_report names its files) rendered from `store` with
/// libjs-dygraphs from `dygraphs_dir`; empty when `name` is no page of a run in the store.
/// Throws InputError as write_report does (the run has no fit, dygraphs not installed).
std::optional<std::string> report_page(Store& store, const std::string& name,
                                       const std::string& dygraphs_dir);

}  // namespace station::report
