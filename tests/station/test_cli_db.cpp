// The CLI and its database file: read commands never create or migrate, a corrupt or foreign
// file is exit 2 naming it and is never written, for every command that opens one.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <iterator>

#include "tests/station/rig_process.hpp"
#include "tests/station/temp_db.hpp"

namespace {

namespace ts = station::testing_support;

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const std::vector<std::string> kReadCommands{"fit --serial X --db ",     "fit --all --run 1 --db ",
                                             "fit --all --db ",          "export --serial X --db ",
                                             "history --serial X --db ", "replay /dev/null --db "};

}  // namespace

TEST(CliDatabase, ReadCommandsOnAMissingPathExit2AndCreateNothing) {
  const auto db = ts::fresh_db("cli-missing");
  for (const auto& cmd : kReadCommands) {
    const auto o = ts::station_command(cmd + db, "cli-db");
    EXPECT_EQ(o.status, 2) << cmd << o.out;
    EXPECT_NE(o.out.find(db), std::string::npos) << cmd << o.out;
    EXPECT_EQ(std::count(o.out.begin(), o.out.end(), '\n'), 1) << cmd << o.out;
    EXPECT_NE(access(db.c_str(), F_OK), 0) << cmd << " created " << db;
  }
}

TEST(CliDatabase, ReadCommandsOnAnEmptyOrForeignFileExit2AndLeaveItAlone) {
  const auto empty = ts::fresh_db("cli-empty");
  std::ofstream(empty).flush();
  const auto foreign = ts::fresh_db("cli-foreign");
  std::ofstream(foreign) << "time_s,rate_dph\n0,1\n";
  for (const auto& path : {empty, foreign}) {
    const std::string before = bytes_of(path);
    for (const auto& cmd : kReadCommands) {
      const auto o = ts::station_command(cmd + path, "cli-db");
      EXPECT_EQ(o.status, 2) << cmd << o.out;
      EXPECT_NE(o.out.find(path), std::string::npos) << cmd << o.out;
    }
    EXPECT_EQ(bytes_of(path), before) << path << " was written to";
    EXPECT_NE(access((path + "-wal").c_str(), F_OK), 0) << "a WAL file appeared for " << path;
  }
}

TEST(CliDatabase, RunRefusesAForeignFileWithoutWritingIt) {
  const auto foreign = ts::fresh_db("cli-run-foreign");
  std::ofstream(foreign) << std::string(8192, 'x');
  const std::string before = bytes_of(foreign);
  const auto o = ts::station_command("run --sim --gyros 1 --db " + foreign, "cli-db");
  EXPECT_EQ(o.status, 2) << o.out;
  EXPECT_NE(o.out.find(foreign), std::string::npos) << o.out;
  EXPECT_EQ(bytes_of(foreign), before);
}
