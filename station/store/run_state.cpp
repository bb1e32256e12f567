// The states of a run (see run_state.hpp).
#include "station/store/run_state.hpp"

namespace station {

namespace {

constexpr std::pair<RunState, std::string_view> kNames[] = {
    {RunState::running, "running"},       {RunState::completed, "completed"},
    {RunState::incomplete, "incomplete"}, {RunState::stopped, "stopped"},
    {RunState::aborted, "aborted"},       {RunState::detached, "detached"},
};

}  // namespace

std::string_view to_string(RunState s) {
  for (const auto& [state, name] : kNames)
    if (state == s) return name;
  return "running";
}

std::optional<RunState> parse_run_state(std::string_view text) {
  for (const auto& [state, name] : kNames)
    if (name == text) return state;
  return std::nullopt;
}

}  // namespace station
