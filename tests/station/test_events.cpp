// Issue 23 point 11: event kinds and run states are types; the documented list of kinds
// (schemas/events.md) is the code's table, row for row, so neither can drift.
#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "station/store/events.hpp"
#include "station/store/run_state.hpp"
#include "text_file.hpp"

namespace {

struct DocRow {
  std::string name, severities, fields;
  bool operator==(const DocRow&) const = default;
};

std::ostream& operator<<(std::ostream& o, const DocRow& r) {
  return o << r.name << " [" << r.severities << "] {" << r.fields << "}";
}

/// "`a`, `b`" -> "a b"; "—" -> "".
std::string backticked_words(const std::string& cell) {
  std::string out;
  const std::regex word("`([a-z_0-9]+)`");
  for (auto it = std::sregex_iterator(cell.begin(), cell.end(), word); it != std::sregex_iterator();
       ++it)
    out += (out.empty() ? "" : " ") + (*it)[1].str();
  return out;
}

/// The rows of the "Kinds" table: | `kind` | info, warn | `field`, … | meaning |.
std::vector<DocRow> documented_kinds() {
  const std::regex row(R"(^\| `([a-z_]+)` \| ([a-z, ]+) \| ([^|]+) \|)");
  std::vector<DocRow> out;
  for (const auto& line : station::testing_support::read_lines(std::string(STATION_SOURCE_DIR) +
                                                               "/schemas/events.md")) {
    std::smatch m;
    if (!std::regex_search(line, m, row)) continue;
    out.push_back({m[1].str(), std::regex_replace(m[2].str(), std::regex(", "), "|"),
                   backticked_words(m[3].str())});
  }
  return out;
}

}  // namespace

TEST(Events, DocumentedListIsTheCodesTable) {
  std::vector<DocRow> code;
  for (const auto& k : station::event_kinds())
    code.push_back({std::string(k.name), std::string(k.severities), std::string(k.data_fields)});
  const auto docs = documented_kinds();
  ASSERT_GE(code.size(), 30u);
  EXPECT_EQ(docs, code) << "schemas/events.md and station/store/events.cpp differ";
}

TEST(Events, KindsAndSeveritiesRoundTripThroughTheirStoredNames) {
  for (const auto& k : station::event_kinds()) {
    EXPECT_EQ(station::to_string(k.kind), k.name);
    EXPECT_EQ(station::parse_event_kind(k.name), k.kind) << k.name;
  }
  EXPECT_FALSE(station::parse_event_kind("back after"));
  for (const auto s : {station::Severity::info, station::Severity::warn, station::Severity::error})
    EXPECT_EQ(station::parse_severity(station::to_string(s)), s);
  EXPECT_FALSE(station::parse_severity("fatal"));
}

TEST(Events, DataMustCarryExactlyTheKindsFieldsAndASeverityItLists) {
  using station::EventKind;
  using station::Severity;
  const nlohmann::json outage{{"device", "can"},
                              {"start_s", 1.0},
                              {"end_s", 4.0},
                              {"ticks_lost", 3},
                              {"ended", "answered"}};
  EXPECT_EQ(station::event_mismatch(EventKind::outage, Severity::warn, outage), "");
  EXPECT_EQ(station::event_mismatch(EventKind::outage, Severity::error, outage), "");
  EXPECT_NE(station::event_mismatch(EventKind::outage, Severity::info, outage), "");
  auto missing = outage;
  missing.erase("ended");
  EXPECT_NE(station::event_mismatch(EventKind::outage, Severity::warn, missing), "");
  EXPECT_NE(station::event_mismatch(EventKind::outage, Severity::warn, nullptr), "");
  EXPECT_EQ(station::event_mismatch(EventKind::safe_hold, Severity::error, nullptr), "");
  EXPECT_NE(station::event_mismatch(EventKind::safe_hold, Severity::error, {{"x", 1}}), "");
}

TEST(RunStates, StoredNamesRoundTripAndUnknownOnesAreRefused) {
  using station::RunState;
  for (const auto s : {RunState::running, RunState::completed, RunState::incomplete,
                       RunState::stopped, RunState::aborted, RunState::detached})
    EXPECT_EQ(station::parse_run_state(station::to_string(s)), s);
  EXPECT_EQ(station::to_string(RunState::completed), "completed");  // stored text unchanged
  EXPECT_FALSE(station::parse_run_state("finished"));
}
