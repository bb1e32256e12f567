// The one start: which run continues, with what, and when a start is refused.
#include "station/daemon/run_start.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "station/common/logging.hpp"
#include "station/daemon/resume.hpp"
#include "station/parts/part_coverage.hpp"

namespace station {

namespace {

void abort_run(Store& store, const RunRecord& run, const std::string& why) {
  store.add_event(run.id, run.last_tick_s.value_or(0), Severity::warn, "seq", EventKind::aborted,
                  why);
  store.finish_run(run.id, RunState::aborted);
}

std::string source_text(const std::optional<std::int64_t>& seed) {
  return seed ? fmt::format("a simulation of seed {}", *seed) : std::string("a rig");
}

/// Rule 2: what keeps `run` from continuing under `request` (empty: nothing).
std::string mismatch(Store& store, const RunRecord& run, const StationConfig& config,
                     const StartRequest& request) {
  if (run.sim_seed != request.sim_seed)
    return fmt::format("run {} was made by {}, this start is {}", run.id, source_text(run.sim_seed),
                       source_text(request.sim_seed));
  if (!request.gyros.empty()) {
    if (const auto diff = gyro_diff(stored_gyros(store, run.id), request.gyros); !diff.empty())
      return fmt::format("run {} was started with other gyros: {}", run.id, diff);
  }
  return resume_mismatch(store, run, config);
}

/// Rule 4: a rig whose devices do not all answer refuses a new run, never a resume.
bool rig_refuses(const StartRequest& request, bool unfinished_run) {
  return !request.rig_problems.empty() && (request.fresh || !unfinished_run);
}

/// Rule 3's gyros: the run's own on the rig as configured now (rule 2 then compares the two).
/// Slots the rig no longer has, or a rig the stored gyros do not fit, are left to rule 2's diff.
StationConfig own_gyros(Store& store, const RunRecord& run, const StationConfig& rig_config) {
  std::vector<SlotGyro> own;
  for (auto& g : stored_gyros(store, run.id))
    if (static_cast<std::size_t>(g.slot) <= rig_config.slots.size()) own.push_back(std::move(g));
  try {
    return with_gyros(rig_config, own);
  } catch (const InputError&) {
    return rig_config;
  }
}

}  // namespace

bool has_unfinished_run(const std::string& db) {
  std::error_code ec;
  if (!std::filesystem::exists(db, ec) || std::filesystem::file_size(db, ec) == 0) return false;
  Store peek(db, OpenMode::read_only);
  return peek.find_unfinished_run().has_value();
}

void refuse_broken_rig(const std::string& db, const StartRequest& request) {
  if (!request.rig_problems.empty() && rig_refuses(request, has_unfinished_run(db)))
    throw InputError::lines(request.rig_problems);
}

StationConfig refuse_bad_gyros(const std::string& db, const StationConfig& config,
                               const StartRequest& request, const std::string& parts_path) {
  const bool new_run = request.fresh || !has_unfinished_run(db);
  const auto problems = gyro_problems(config, request.gyros,
                                      parts_path.empty() ? config.parts_path : parts_path, new_run);
  if (!problems.empty()) throw InputError::lines(problems);
  if (!new_run) return config;
  StationConfig named = with_gyros(config, request.gyros);
  warn_slots_without_part(named, parts_path);  // before any device: judged against nothing
  return named;
}

StartPlan start_run(Store& store, const StationConfig& rig_config, const StartRequest& request) {
  StartPlan plan{std::nullopt, request.protocol, std::nullopt, {}, rig_config};
  auto run = store.find_unfinished_run();
  if (!run && request.resume_only) return plan;
  // Rule 4 first: a refused start changes nothing, not even the run --new would supersede.
  if (rig_refuses(request, run.has_value())) throw InputError::lines(request.rig_problems);
  if (!run || request.fresh) {
    plan.config = with_gyros(rig_config, request.gyros);  // refused before --new aborts a run
    if (run) abort_run(store, *run, "superseded by a new run (--new)");
    return plan;
  }
  plan.config = own_gyros(store, *run, rig_config);
  if (const auto why = mismatch(store, *run, plan.config, request); !why.empty())
    throw InputError(
        fmt::format("{}: {}; start a new run with --new (the old one is then marked aborted)",
                    store.db().path(), why));
  plan.protocol = parse_protocol(run->protocol_text,
                                 fmt::format("{}:run {} protocol", store.db().path(), run->id));
  if (!request.protocol.text.empty() && plan.protocol.text != request.protocol.text)
    plan.warnings.push_back(
        fmt::format("run {} continues with the protocol stored with it ('{}'), "
                    "not '{}'",
                    run->id, plan.protocol.name, request.protocol.name));
  for (const auto& line : request.rig_problems)
    plan.warnings.push_back(fmt::format("resuming without: {}", line));
  if (run->sim_seed) plan.replay_until_t_s = run->last_tick_s.value_or(-1.0);
  for (const auto& w : plan.warnings) log("seq")->warn("{}", w);
  plan.resume = std::move(run);
  return plan;
}

}  // namespace station
