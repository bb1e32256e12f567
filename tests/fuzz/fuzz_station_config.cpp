// Fuzz target: the station configuration parser (station/config/config.*, toml_reader.*).
// Input: the text of a station TOML file.
// Property: no crash, UB or hang; every rejection is an InputError of one line naming the file (the
// one-line, exit-2 error main() prints); any other exception escaping is a finding.
#include <cstdint>
#include <exception>
#include <string>
#include <typeinfo>

#include "fuzz_check.hpp"
#include "station/config/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto config = station::parse_station_config(text, "fuzz.toml");
    station::fuzz::check(!config.slots.empty(), "a config without slots was accepted");
  } catch (const station::InputError& e) {
    // The expected rejection: one line that names the file first.
    const std::string what = e.what();
    station::fuzz::check(what.rfind("fuzz.toml", 0) == 0 && what.find('\n') == std::string::npos,
                         "an error that is not one line naming the file: " + what);
  } catch (const std::exception& e) {
    station::fuzz::check(
        false, std::string("non-InputError escaped (") + typeid(e).name() + "): " + e.what());
  }
  return 0;
}
