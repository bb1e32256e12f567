// Fuzz target: the CSV reader of `analyze` and `adev` (station/cli/csv_table.*). Input: a CSV
// file's bytes; it asks for the columns time_s and rate_dph, then checks time increases.
// Property: no crash, UB or hang; every rejection is an InputError of one line naming the file;
// accepted columns are finite and as long as the row list.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <typeinfo>

#include "fuzz_check.hpp"
#include "station/cli/csv_table.hpp"

using station::fuzz::check;

namespace {

// read_csv_columns reads a path: each run writes the input to one file of this process.
const std::string& scratch_path() {
  static const std::string path = "/tmp/fuzz_csv_table-" + std::to_string(getpid()) + ".csv";
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FILE* f = std::fopen(scratch_path().c_str(), "wb");
  if (f == nullptr) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const auto t = station::read_csv_columns(scratch_path(), {"time_s", "rate_dph"});
    check(t.columns.size() == 2, "not two columns");
    for (const auto& c : t.columns) {
      check(c.size() == t.lines.size(), "a column and the line list differ in length");
      for (double v : c) check(std::isfinite(v), "a non-finite cell was accepted");
    }
    station::require_increasing(t, 0);
  } catch (const station::InputError& e) {
    // The expected rejection: one line that names the file first.
    const std::string what = e.what();
    check(what.rfind(scratch_path(), 0) == 0 && what.find('\n') == std::string::npos,
          "an error that is not one line naming the file: " + what);
  } catch (const std::exception& e) {
    check(false, std::string("non-InputError escaped (") + typeid(e).name() + "): " + e.what());
  }
  return 0;
}
