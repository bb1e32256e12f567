// The time-left rule (time_left.hpp).
#include "station/daemon/time_left.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace station {
namespace {

/// The current step's remainder, s (empty: unknown).
std::optional<double> step_left_s(const Step& s, std::optional<double> nominal_s,
                                  const StepPosition& at) {
  if (s.kind == StepKind::set_temperature && s.ramp_c_per_h > 0 && at.ramp_point_c &&
      at.ramp_target_c)
    return std::abs(*at.ramp_target_c - *at.ramp_point_c) / s.ramp_c_per_h * 3600.0;
  if (!nominal_s) return std::nullopt;
  return std::max(0.0, *nominal_s - at.in_step_s);
}

}  // namespace

std::optional<double> time_left_s(const Protocol& p, const StepPosition& at) {
  const auto steps = static_cast<int>(p.steps.size());
  if (at.step_index >= steps) return 0.0;
  if (at.step_index < 0) return std::nullopt;
  const auto nominal = p.nominal_step_durations_s(at.start_c);
  const auto i = static_cast<std::size_t>(at.step_index);
  auto left = step_left_s(p.steps[i], nominal[i], at);
  for (std::size_t k = i + 1; left && k < nominal.size(); ++k)
    left = nominal[k] ? std::optional(*left + *nominal[k]) : std::nullopt;
  return left;
}

std::string time_left_text(double left_s) {
  const auto minutes = static_cast<long>(std::ceil(std::max(0.0, left_s) / 60.0));
  if (left_s < 60.0) return "under 1 min left";
  if (minutes < 60) return fmt::format("{} min left", minutes);
  return fmt::format("{} h {} min left", minutes / 60, minutes % 60);
}

}  // namespace station
