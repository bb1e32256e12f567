// The one exception type for bad user input (CSV, config, protocol files): its message names
// the file, the line and the key or column. main() turns it into one line and exit status 2.
#pragma once

#include <stdexcept>

namespace station {

/// Bad user input; what() reads "FILE:LINE: key 'a.b': what is wrong".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace station
