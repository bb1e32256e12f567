// Writing the rig's outputs where they change.
#include "station/daemon/outputs.hpp"

#include <utility>
#include <vector>

namespace station {

namespace dr = station::drivers;

std::vector<std::string> RigOutputs::write(const SafetyOutputs& o) {
  std::vector<std::string> failures;
  if (bank_ == nullptr) return failures;
  std::vector<std::pair<std::string, bool>> lines{
      {std::string(dr::gpio::roles::tower_red), o.red},
      {std::string(dr::gpio::roles::tower_amber), o.amber},
      {std::string(dr::gpio::roles::tower_green), o.green}};
  for (std::size_t i = 0; i < slots_; ++i)
    lines.emplace_back(dr::gpio::roles::relay(static_cast<int>(i + 1)), o.gyro_power);
  for (const auto& [role, on] : lines) {
    const auto it = written_.find(role);
    if ((it != written_.end() && it->second == on) ||
        dr::gpio::find_role(bank_->config(), role) == nullptr)
      continue;
    if (auto r = bank_->write(role, on); r) {
      written_[role] = on;
    } else {
      failures.push_back(r.error().message);
    }
  }
  return failures;
}

}  // namespace station
