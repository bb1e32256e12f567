// What the routes read from a request: ids in the path, numbers in the query, string fields of a
// JSON body. Each answers 400 (or reports why) in the API's one wording.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace station::http {

/// A positive decimal integer in its one canonical form (digits, no leading zero, sign, space,
/// fraction or exponent: "01", "+1", " 1", "1.0" are refused), or nullopt.
std::optional<std::int64_t> positive_int(const std::string& text);

/// A decimal integer >= 0 in its canonical form ("0", or as positive_int), or nullopt.
std::optional<std::int64_t> non_negative_int(const std::string& text);

/// The path's first capture as a positive id, or nullopt with a 400 answered naming `what`
/// ("run id", "fit id").
std::optional<std::int64_t> path_id(const httplib::Request& req, httplib::Response& res,
                                    const char* what);

/// A string field of a JSON object body: nullopt when absent or wrong (then `error` says why:
/// not a string, longer than `max_len` bytes, or text the text rule refuses (note_problem:
/// a control, a bidirectional control, naming it as U+XXXX and its position)).
std::optional<std::string> string_field(const nlohmann::json& body, const char* key,
                                        std::size_t max_len, std::string& error);

/// A JSON body's keys checked against the ones its route knows: the first unknown key named in
/// `error` ("field 'x': unknown (expected one of: by, note, override)"), true when none.
bool known_keys_only(const nlohmann::json& body, std::initializer_list<const char*> known,
                     std::string& error);

}  // namespace station::http
