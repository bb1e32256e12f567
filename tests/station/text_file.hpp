// Test helpers: a text file as lines and back (session logs, headers).
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace station::testing_support {

inline std::vector<std::string> read_lines(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

inline void write_lines(const std::filesystem::path& p, const std::vector<std::string>& lines) {
  std::ofstream out(p);
  for (const auto& l : lines) out << l << '\n';
}

}  // namespace station::testing_support
