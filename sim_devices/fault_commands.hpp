// Fault injection by text command, for a person at simrig's control socket and for tests: one
// command line in, one reply line out ("ok" or "ok DETAIL", or "error: WHAT").
#pragma once

#include <string>
#include <string_view>

namespace station::sim {

class SimWorld;

/// The command list, one "syntax  what it does" line each (simrig --help, docs/SIMRIG.md).
std::string fault_command_help();

/// Runs one command line against `world` (see fault_command_help); never throws. Injected
/// faults stay until cleared by the opposite command, `DEVICE clear` or `clear`. Call from the
/// thread that steps the world (SimWorld replaces its CAN bus when a station reconnects).
std::string run_fault_command(SimWorld& world, std::string_view line);

}  // namespace station::sim
