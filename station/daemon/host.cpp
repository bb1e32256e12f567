// The host: one start, one run loop, one idle look, on one rig, store and clock.
#include "station/daemon/host.hpp"

namespace station {

Host::Host(const StationConfig& config, Rig& rig, Store& store, drivers::Clock& clock,
           std::function<void(const RunEvent&)> on_event)
    : config_(config),
      rig_(rig),
      store_(store),
      clock_(clock),
      idle_(rig, store, std::move(on_event)) {}

RunOutcome Host::run(const StartPlan& plan, SequencerOptions options) {
  options.replay_until_t_s = plan.replay_until_t_s;
  Sequencer seq(plan.config, plan.protocol, rig_, store_, clock_, std::move(options));
  try {
    const RunOutcome out = seq.run(plan.resume);
    idle_.run_ended();  // the run drove the lamps: the next idle look writes them again
    return out;
  } catch (...) {
    idle_.run_ended();  // a failed run (the store) left them dark: the same
    throw;
  }
}

}  // namespace station
