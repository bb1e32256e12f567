// Test helper: a fresh SQLite path per test process (ctest runs tests in parallel processes).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <string>

namespace station::testing_support {

/// TempDir/NAME-PID.db with any old database, WAL and shared-memory file removed.
inline std::string fresh_db(const std::string& name) {
  const std::string path = ::testing::TempDir() + name + "-" + std::to_string(getpid()) + ".db";
  for (const char* ext : {"", "-wal", "-shm"}) std::remove((path + ext).c_str());
  return path;
}

}  // namespace station::testing_support
