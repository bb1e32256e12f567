// The API's bearer token: one line in a file the daemon creates at its first start with mode
// 0600 (random, 256 bits from getrandom(2)); a file readable by group or others is refused, as
// ssh refuses such a key.
#pragma once

#include <string>
#include <string_view>

namespace station::http {

/// Reads the token at `path`, creating the file first if it does not exist. Throws InputError
/// (naming the file) when it cannot be created or read, is empty, or is group/other-readable.
std::string load_or_create_token(const std::string& path);

/// Whether an Authorization header value is "Bearer <token>" (compared in constant time).
bool bearer_matches(std::string_view header, std::string_view token);

}  // namespace station::http
