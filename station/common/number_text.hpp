// Numbers in messages that compare a value with a limit: a limit as it was written, a value with
// enough digits to be told from the limit it is compared with ("1000.0001 above 1000", never
// "1000 above 1000").
#pragma once

#include <string>

namespace station {

/// `v` as written: the shortest text that reads back as the same double ("1000.0001", "0.1",
/// "1e+20"; fmt's `{}`).
std::string as_written(double v);

/// `v` with `digits` significant digits, or more where fewer would read as `limit` or on the
/// other side of it; at most as_written(v).
std::string beside_limit(double v, double limit, int digits);

}  // namespace station
