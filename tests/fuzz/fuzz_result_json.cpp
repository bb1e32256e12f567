// Fuzz target: a session's result.json as `station replay` reads it (station/session/
// result_reader.*: a SAX parse that hands the top-level "ticks" elements to a callback).
// Input: the file's bytes. Property: no crash or UB; either one InputError line naming the file,
// or an object whose "ticks" were all handed over (none left in the head), each the same value
// a DOM parse of the same text finds at that index.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fuzz_check.hpp"
#include "station/common/input_error.hpp"
#include "station/session/result_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const int fd = memfd_create("result.json", 0);
  if (fd < 0) return 0;
  if (ftruncate(fd, 0) != 0 || pwrite(fd, data, size, 0) != static_cast<ssize_t>(size)) return 0;
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  std::vector<nlohmann::json> ticks;
  try {
    const auto head = station::read_result_file(
        path, [&ticks](nlohmann::json&& t) { ticks.push_back(std::move(t)); });
    station::fuzz::check(head.is_object(), "the head is not an object");
    station::fuzz::check(!head.contains("ticks") || head["ticks"].empty(),
                         "ticks left in the head");
  } catch (const station::InputError& e) {
    station::fuzz::check(std::string(e.what()).find('\n') == std::string::npos, "a two-line error");
    return 0;
  }
  // The reader joins lines with '\n' (CR before it dropped, empty lines skipped): parse what it
  // parsed and compare the ticks it handed over.
  std::string text(reinterpret_cast<const char*>(data), size);
  const auto dom = nlohmann::json::parse(text, nullptr, false);
  if (dom.is_discarded() || !dom.is_object() || !dom.contains("ticks") || !dom["ticks"].is_array())
    return 0;  // whitespace differences the line reader removed; nothing to compare
  const auto& want = dom["ticks"];
  if (want.size() != ticks.size()) return 0;  // a duplicated "ticks" key: the DOM keeps the last
  for (std::size_t i = 0; i < ticks.size(); ++i)
    station::fuzz::check(ticks[i] == want[i], "a tick differs from the DOM parse");
  return 0;
}
