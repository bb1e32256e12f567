// Resume decisions: same slots, stored protocol, explicit abort of superseded runs.
#include "station/daemon/resume.hpp"

#include <fmt/format.h>

namespace station {
namespace {

void abort_run(Store& store, const RunRecord& run, const std::string& why) {
  store.add_event(run.id, run.progress.t_s, "warn", "seq", "aborted", why);
  store.finish_run(run.id, "aborted");
}

}  // namespace

std::string resume_mismatch(Store& store, const RunRecord& run, const StationConfig& config) {
  const auto stored = store.run_slots(run.id);
  std::string now, then;
  for (const auto& s : config.slots) now += fmt::format(" {}@{}", s.serial, s.node);
  for (const auto& s : stored) then += fmt::format(" {}@{}", s.serial, s.node);
  if (now == then) return {};
  return fmt::format("run {} was started with slots{} but the configuration has{}", run.id, then,
                     now);
}

ResumeDecision decide_resume(Store& store, const StationConfig& config, bool fresh,
                             bool abort_mismatch) {
  ResumeDecision d;
  auto run = store.find_unfinished_run();
  if (!run) return d;
  if (fresh) {
    abort_run(store, *run, "superseded by a new run (--new)");
    return d;
  }
  if (const auto why = resume_mismatch(store, *run, config); !why.empty()) {
    if (!abort_mismatch) {
      throw InputError(
          fmt::format("{}: {}; start a new run with --new (the old one is then "
                      "marked aborted)",
                      store.db().path(), why));
    }
    abort_run(store, *run, why);
    return d;
  }
  d.protocol = parse_protocol(run->protocol_text,
                              fmt::format("{}:run {} protocol", store.db().path(), run->id));
  d.run = std::move(run);
  return d;
}

}  // namespace station
