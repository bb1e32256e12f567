// The gyros of a run: given at start, checked before anything moves, stored with the run.
#include "station/daemon/run_gyros.hpp"

#include <fmt/format.h>

#include <charconv>
#include <map>
#include <optional>
#include <set>

#include "station/common/text_rule.hpp"
#include "station/parts/part_file.hpp"
#include "station/store/fit_verdicts.hpp"

namespace station {

namespace {

/// "slot N (node K)": how a message names a slot of `config`.
std::string slot_name(const StationConfig& config, int slot) {
  return fmt::format("slot {} (node {})", slot,
                     config.slots[static_cast<std::size_t>(slot - 1)].node);
}

bool has_slot(const StationConfig& config, int slot) {
  return slot >= 1 && static_cast<std::size_t>(slot) <= config.slots.size();
}

/// Slot numbers, given twice, text rule: what needs neither the part file nor the defaults.
void check_given(const StationConfig& config, const std::vector<SlotGyro>& given,
                 std::vector<std::string>& out) {
  std::set<int> seen;
  for (const auto& g : given) {
    if (!has_slot(config, g.slot)) {
      out.push_back(fmt::format("slot {}: the configuration {} has slots 1..{}", g.slot,
                                config.path, config.slots.size()));
      continue;
    }
    if (!seen.insert(g.slot).second) out.push_back(fmt::format("slot {}: given twice", g.slot));
    if (const auto p = identifier_problem(g.serial))
      out.push_back(fmt::format("{}: serial '{}': {}", slot_name(config, g.slot),
                                ascii_escaped(g.serial), *p));
    if (const auto p = g.part.empty() ? std::nullopt : identifier_problem(g.part))
      out.push_back(
          fmt::format("{}: part '{}': {}", slot_name(config, g.slot), ascii_escaped(g.part), *p));
  }
}

/// Each slot's gyro after `given` (the configuration's default where none is given).
std::vector<SlotGyro> merged(const StationConfig& config, const std::vector<SlotGyro>& given) {
  std::vector<SlotGyro> out;
  for (std::size_t i = 0; i < config.slots.size(); ++i)
    out.push_back({static_cast<int>(i + 1), config.slots[i].serial, config.slots[i].part});
  for (const auto& g : given) {
    if (!has_slot(config, g.slot)) continue;
    auto& m = out[static_cast<std::size_t>(g.slot - 1)];
    m.serial = g.serial;
    if (!g.part.empty()) m.part = g.part;  // none given: the configuration's part stays
  }
  return out;
}

/// A serial on two slots, a slot with none.
void check_merged(const StationConfig& config, const std::vector<SlotGyro>& gyros,
                  std::vector<std::string>& out) {
  std::map<std::string, int> first_slot;
  for (const auto& g : gyros) {
    if (g.serial.empty()) {
      out.push_back(fmt::format(
          "{}: no serial (the configuration names none): give it at start, e.g. --slot {}=SERIAL",
          slot_name(config, g.slot), g.slot));
      continue;
    }
    const auto [it, fresh] = first_slot.emplace(g.serial, g.slot);
    if (!fresh)
      out.push_back(fmt::format("{}: serial '{}' is on slot {} as well", slot_name(config, g.slot),
                                g.serial, it->second));
  }
}

/// Parts the part file lacks, or parts with no part file.
void check_parts(const StationConfig& config, const std::vector<SlotGyro>& given,
                 const std::string& parts_path, std::vector<std::string>& out) {
  std::optional<PartFile> file;
  for (const auto& g : given) {
    if (g.part.empty() || !has_slot(config, g.slot)) continue;
    if (parts_path.empty()) {
      out.push_back(fmt::format("{}: part '{}' but no part file (give [station] parts or --parts)",
                                slot_name(config, g.slot), g.part));
      continue;
    }
    if (!file) file = load_part_file(parts_path);
    if (!file->parts.contains(g.part)) {
      std::string known;
      for (const auto& [n, p] : file->parts) known += (known.empty() ? "" : ", ") + n;
      out.push_back(fmt::format("{}: part '{}' is not in {} (it has: {})",
                                slot_name(config, g.slot), g.part, parts_path, known));
    }
  }
}

}  // namespace

std::optional<int> slot_number(const std::string& text) {
  const bool digits = !text.empty() && text.size() <= 3 && text[0] != '0' &&
                      text.find_first_not_of("0123456789") == std::string::npos;
  return digits ? std::optional<int>(std::stoi(text)) : std::nullopt;
}

SlotGyro parse_slot_gyro(const std::string& text, const std::string& where) {
  const auto eq = text.find('=');
  const auto slot = eq == std::string::npos ? std::nullopt : slot_number(text.substr(0, eq));
  if (!slot)
    throw InputError(fmt::format("{} '{}': expected N=SERIAL or N=SERIAL,PART (N the slot, from 1)",
                                 where, ascii_escaped(text)));
  const std::string rest = text.substr(eq + 1);
  const auto comma = rest.find(',');
  SlotGyro g{*slot, rest.substr(0, comma),
             comma == std::string::npos ? "" : rest.substr(comma + 1)};
  if (const auto p = identifier_problem(g.serial))
    throw InputError(fmt::format("{} '{}': serial: {}", where, ascii_escaped(text), *p));
  if (comma != std::string::npos)
    if (const auto p = identifier_problem(g.part))
      throw InputError(fmt::format("{} '{}': part: {}", where, ascii_escaped(text), *p));
  return g;
}

std::vector<std::string> gyro_problems(const StationConfig& config,
                                       const std::vector<SlotGyro>& given,
                                       const std::string& parts_path, bool new_run) {
  std::vector<std::string> out;
  check_given(config, given, out);
  if (!out.empty()) return out;  // the rest would repeat a bad slot's lines
  if (new_run) check_merged(config, merged(config, given), out);
  try {
    check_parts(config, given, parts_path, out);
  } catch (const InputError& e) {
    out.push_back(e.what());
  }
  return out;
}

StationConfig with_gyros(const StationConfig& config, const std::vector<SlotGyro>& gyros) {
  std::vector<std::string> problems;
  check_given(config, gyros, problems);
  if (problems.empty()) check_merged(config, merged(config, gyros), problems);
  if (!problems.empty()) throw InputError::lines(problems);
  StationConfig out = config;
  for (const auto& g : gyros) {
    auto& s = out.slots[static_cast<std::size_t>(g.slot - 1)];
    s.serial = g.serial;
    s.gyro_given = true;
    if (g.part.empty()) continue;  // the configuration's part (its default) stays
    s.part = g.part;
    s.part_line = 0;
  }
  return out;
}

std::vector<SlotGyro> stored_gyros(Store& store, std::int64_t run_id) {
  std::vector<SlotGyro> out;
  for (const auto& s : store.run_slots(run_id)) {
    const auto part = find_run_part(store, s.serial, {run_id});
    out.push_back({s.slot + 1, s.serial, part ? part->part_number : ""});
  }
  return out;
}

std::string gyro_diff(const std::vector<SlotGyro>& stored, const std::vector<SlotGyro>& given) {
  std::string out;
  const auto add = [&out](const std::string& part) { out += (out.empty() ? "" : "; ") + part; };
  for (const auto& g : given) {
    const SlotGyro* then = nullptr;
    for (const auto& s : stored) then = s.slot == g.slot ? &s : then;
    if (then == nullptr) {
      add(fmt::format("slot {} added ('{}')", g.slot, g.serial));
      continue;
    }
    if (then->serial != g.serial)
      add(fmt::format("slot {} serial '{}' -> '{}'", g.slot, then->serial, g.serial));
    if (!g.part.empty() && then->part != g.part)
      add(fmt::format("slot {} part '{}' -> '{}'", g.slot, then->part, g.part));
  }
  return out;
}

}  // namespace station
