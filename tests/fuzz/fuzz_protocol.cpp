// Fuzz target: the test-protocol parser (station/config/protocol.*). Input: the text of a
// protocol TOML file.
// Property: no crash, UB or hang; every rejection is an InputError of one line naming the file; an
// accepted protocol has steps and a nominal duration that is a number.
#include <cmath>
#include <cstdint>
#include <exception>
#include <string>
#include <typeinfo>

#include "fuzz_check.hpp"
#include "station/config/protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto p = station::parse_protocol(text, "fuzz.toml");
    station::fuzz::check(!p.steps.empty(), "a protocol without steps was accepted");
    station::fuzz::check(!std::isnan(p.nominal_duration_s(25.0)), "nominal duration is NaN");
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
