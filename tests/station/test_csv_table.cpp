// CSV reader: every error path names the file, the line and the column.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "station/cli/csv_table.hpp"

namespace {

// ctest runs every test as its own process, in parallel: each gets its own directory.
std::string write_temp(const std::string& name, const std::string& text) {
  const std::string dir = testing::TempDir() + "csv-" + std::to_string(getpid());
  mkdir(dir.c_str(), 0755);
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// Returns the InputError message of reading `text` (empty when it does not throw).
std::string error_of(const std::string& text,
                     std::vector<std::string> cols = {"time_s", "rate_dph"}) {
  const auto path = write_temp("csv_err.csv", text);
  try {
    auto t = station::read_csv_columns(path, cols);
    station::require_increasing(t, 0);
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(CsvTable, ReadsColumnsByNameSkippingCommentsAndBlanks) {
  const auto path =
      write_temp("ok.csv", "# comment\ntemp_c,time_s,rate_dph\n\n1.5,0,10\n2.5,1,11\r\n");
  const auto t = station::read_csv_columns(path, {"time_s", "temp_c"});
  ASSERT_EQ(t.lines.size(), 2u);
  EXPECT_EQ(t.lines[0], 4u);
  EXPECT_EQ(t.lines[1], 5u);
  EXPECT_DOUBLE_EQ(t[0][1], 1.0);
  EXPECT_DOUBLE_EQ(t[1][0], 1.5);
}

TEST(CsvTable, MissingColumnNamesTheHeaderLine) {
  const auto msg = error_of("time_s,temp_c\n0,1\n");
  EXPECT_NE(msg.find("csv_err.csv:1: no column 'rate_dph'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("columns: time_s, temp_c"), std::string::npos) << msg;
}

TEST(CsvTable, NonNumericCellNamesLineAndColumn) {
  const auto msg = error_of("time_s,rate_dph\n0,1\n1,abc\n");
  EXPECT_NE(msg.find("csv_err.csv:3: column 'rate_dph': not a number: 'abc'"), std::string::npos)
      << msg;
}

TEST(CsvTable, NanAndInfinityAreRejected) {
  EXPECT_NE(error_of("time_s,rate_dph\n0,nan\n").find(":2: column 'rate_dph': not a finite"),
            std::string::npos);
  EXPECT_NE(error_of("time_s,rate_dph\n0,1\n1,-inf\n").find(":3: column 'rate_dph'"),
            std::string::npos);
}

TEST(CsvTable, EmptyCellAndRaggedRow) {
  EXPECT_NE(error_of("time_s,rate_dph\n0,\n").find(":2: column 'rate_dph': empty cell"),
            std::string::npos);
  EXPECT_NE(error_of("time_s,rate_dph\n0,1,2\n").find(":2: 3 cells where the header has 2"),
            std::string::npos);
}

TEST(CsvTable, TimeGoingBackwardsNamesTheRow) {
  const auto msg = error_of("time_s,rate_dph\n0,1\n1,1\n# note\n0.5,1\n");
  EXPECT_NE(msg.find("csv_err.csv:5: column 'time_s': 0.5 does not increase"), std::string::npos)
      << msg;
}

TEST(CsvTable, MissingFileAndEmptyFile) {
  EXPECT_NE(error_of("").find("no header row"), std::string::npos);
  EXPECT_THROW(station::read_csv_columns("/nonexistent/x.csv", {"a"}), station::InputError);
}
