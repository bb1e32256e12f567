// What the routes read from a request (see route_params.hpp).
#include "station/http/route_params.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>

#include "station/common/text_rule.hpp"
#include "station/http/json_reply.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen headers included after it.
#include <httplib.h>

namespace station::http {

std::optional<std::int64_t> positive_int(const std::string& text) {
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || text.front() == '0' || ec != std::errc() ||
      end != text.data() + text.size() || v <= 0)
    return std::nullopt;
  return v;
}

std::optional<std::int64_t> non_negative_int(const std::string& text) {
  return text == "0" ? std::optional<std::int64_t>(0) : positive_int(text);
}

std::optional<std::int64_t> path_id(const httplib::Request& req, httplib::Response& res,
                                    const char* what) {
  const auto id = positive_int(req.matches[1].str());
  if (!id)
    send_json(res, 400,
              {{"error",
                fmt::format("{} '{}': expected a positive integer", what, req.matches[1].str())}});
  return id;
}

std::optional<std::string> string_field(const nlohmann::json& body, const char* key,
                                        std::size_t max_len, std::string& error) {
  if (!body.contains(key)) return std::nullopt;
  if (!body[key].is_string() || body[key].get<std::string>().size() > max_len) {
    error = fmt::format("field '{}': expected a string of at most {} bytes", key, max_len);
    return std::nullopt;
  }
  std::string text = body[key].get<std::string>();
  // The one text rule where text enters (common/text_rule.hpp): a NUL, a newline or a
  // bidirectional control is refused here, as on the command line.
  if (const auto problem = note_problem(text, max_len)) {
    error = fmt::format("field '{}': {}", key, *problem);
    return std::nullopt;
  }
  return text;
}

bool known_keys_only(const nlohmann::json& body, std::initializer_list<const char*> known,
                     std::string& error) {
  for (const auto& [key, value] : body.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    error = known.size() == 0 ? fmt::format("field '{}': unknown (this request takes no fields)",
                                            key.substr(0, 80))
                              : fmt::format("field '{}': unknown (expected one of: {})",
                                            key.substr(0, 80), fmt::join(known, ", "));
    return false;
  }
  return true;
}

}  // namespace station::http
