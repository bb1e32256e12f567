// Reading a session's result.json: a SAX parse (nlohmann) builds the head (state, bins, events,
// fits) as a tree and hands each tick to a callback as it completes, so no document tree of the
// whole file (four times its text) is ever built.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace station {

/// Parses `path` (or `path`.gz); calls `on_tick` with every element of the top-level "ticks"
/// array in order and returns the rest of the document ("ticks" left empty). Throws InputError
/// "FILE: byte N: what" when the text is not JSON or its top level is not an object.
nlohmann::json read_result_file(const std::string& path,
                                const std::function<void(nlohmann::json&&)>& on_tick);

class LogLineReader;

/// The same, from `reader` (SessionReads: verified as it is read).
nlohmann::json read_result_file(LogLineReader& reader,
                                const std::function<void(nlohmann::json&&)>& on_tick);

}  // namespace station
