// A report page by its file name (report_page.hpp).
#include "station/report/report_page.hpp"

#include <fmt/format.h>

#include <charconv>

#include "station/report/report.hpp"
#include "station/report/report_html.hpp"
#include "station/report/report_load.hpp"

namespace station::report {
namespace {

/// The run id a page name starts with ("run-12.html", "run-12-slot1-SN.html"), in plain digits.
std::optional<std::int64_t> run_of_page(const std::string& name) {
  if (!name.starts_with("run-")) return std::nullopt;
  const char* first = name.data() + 4;
  std::int64_t id = 0;
  const auto [end, ec] = std::from_chars(first, name.data() + name.size(), id);
  if (ec != std::errc() || end == first || *first == '0' || id <= 0) return std::nullopt;
  return id;
}

}  // namespace

std::string index_page_name(std::int64_t run_id) {
  return fmt::format("run-{}.html", run_id);
}

std::string serial_page_name(std::int64_t run_id, int slot, const std::string& serial) {
  return fmt::format("run-{}-slot{}-{}.html", run_id, slot, file_safe(serial));
}

std::optional<std::string> report_page(Store& store, const std::string& name,
                                       const std::string& dygraphs_dir) {
  const auto run_id = run_of_page(name);
  if (!run_id || !store.find_run(*run_id)) return std::nullopt;
  // The name is one of the run's before anything is loaded: a wrong name costs one query.
  bool known = name == index_page_name(*run_id);
  for (const auto& s : store.run_slots(*run_id))
    known = known || name == serial_page_name(*run_id, s.slot, s.serial);
  for (const auto p :
       {AcceptancePage::scale_factor, AcceptancePage::turn_on, AcceptancePage::positions})
    known = known || name == acceptance_page_name(*run_id, p);
  if (!known) return std::nullopt;
  const RunReport r = load_report(store, *run_id);
  std::vector<std::string> names;
  for (const auto& s : r.serials)
    names.push_back(s.fit ? serial_page_name(r.run.id, s.slot.slot, s.slot.serial) : "");
  const Assets assets =
      read_dygraphs(dygraphs_dir.empty() ? std::string(kDygraphsDir) : dygraphs_dir);
  if (name == index_page_name(r.run.id)) return index_html(r, assets, names);
  for (std::size_t i = 0; i < r.serials.size(); ++i)
    if (!names[i].empty() && name == names[i]) return serial_html(r, r.serials[i], assets);
  for (const auto p : acceptance_pages(r.acceptance))
    if (name == acceptance_page_name(r.run.id, p)) return acceptance_html(r, p, assets);
  return std::nullopt;
}

}  // namespace station::report
