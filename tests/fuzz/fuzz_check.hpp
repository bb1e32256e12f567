// What a fuzz target does when a property breaks: say which, and abort so libFuzzer keeps the
// input (crash-<sha1>) and the stack.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace station::fuzz {

/// Aborts with `what` on stderr unless `ok`.
inline void check(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz property broken: %s\n", what.c_str());
  std::abort();
}

}  // namespace station::fuzz
