// The states of a run (runs.state) and how a run can end.
#pragma once

#include <optional>
#include <string_view>

namespace station {

/// A run's state. Stored: running, completed, incomplete, stopped, aborted. `detached` is an
/// outcome only: the run stays 'running' in the store for the next daemon to resume.
enum class RunState { running, completed, incomplete, stopped, aborted, detached };

/// The stored name ("completed").
std::string_view to_string(RunState s);
/// The state a stored name names, or nullopt.
std::optional<RunState> parse_run_state(std::string_view text);

}  // namespace station
