// The HTTP room's one way to answer with JSON (http_server.cpp defines it; the routes share it).
#pragma once

#include <nlohmann/json.hpp>

namespace httplib {
struct Response;
}

namespace station::http {

/// Sets `status` and `body` as application/json (invalid UTF-8 replaced, never thrown).
void send_json(httplib::Response& res, int status, const nlohmann::json& body);

}  // namespace station::http
