// The gyros of a run (issue 35): the configuration is the rig (nodes, axes, pulse weights); the
// serial and part number on each slot belong to the run. They are given at start (`run --slot
// 1=SN,PN`, the API's "slots", the live page's start form) or default to the serials the
// configuration still names; a slot with neither is refused at start. Slots are numbered from 1
// in the order of the configuration's [[slot]] tables (as the relays are).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "station/config/config.hpp"
#include "station/store/store.hpp"

namespace station {

/// A gyro mounted on a slot for one run.
struct SlotGyro {
  int slot = 0;        ///< 1-based, the order of [[slot]] tables
  std::string serial;  ///< the gyro's serial number (an identifier, text_rule)
  std::string part;    ///< its part number (a key of the part file); empty: the slot's default
  bool operator==(const SlotGyro&) const = default;
};

/// A slot's number as people give it (--slot N=..., the API's "slots" keys): 1..999 in plain
/// digits, no sign, no leading zero; nullopt otherwise. The one rule for both.
std::optional<int> slot_number(const std::string& text);

/// `N=SERIAL[,PART]` (the --slot option, `where` names it in errors); throws InputError.
SlotGyro parse_slot_gyro(const std::string& text, const std::string& where);

/// What is wrong with the gyros `given` at start on `config`, one line each: a slot the
/// configuration lacks or one given twice, a serial or part failing the text rule, a part the
/// part file at `parts_path` lacks (or a part with no part file), and for a `new_run` a serial
/// on two slots (with the configuration's defaults for the slots not given) or a slot left
/// without a serial (a resume keeps its own: run_start.hpp). Reads the part file (an unreadable
/// one is a line too); empty: the gyros can start.
std::vector<std::string> gyro_problems(const StationConfig& config,
                                       const std::vector<SlotGyro>& given,
                                       const std::string& parts_path, bool new_run);

/// `config` with `gyros` on their slots (serial, and part where one is given: a gyro given
/// without one keeps the configuration's part for its slot; marked given at start). Throws
/// InputError::lines with the problems of gyro_problems that need no part file.
StationConfig with_gyros(const StationConfig& config, const std::vector<SlotGyro>& gyros);

/// The gyros stored with run `run_id` (run_slots: serial and part number per slot).
std::vector<SlotGyro> stored_gyros(Store& store, std::int64_t run_id);

/// One line naming each difference between the gyros a run stored and those `given` at a
/// start that would continue it ("slot 1 serial 'A' -> 'B'"; a part only where one is given);
/// empty when every given gyro is the stored one.
std::string gyro_diff(const std::vector<SlotGyro>& stored, const std::vector<SlotGyro>& given);

}  // namespace station
