// What an F4T's part number says about the controller (CCL watlowf4t.py process_controller:
// 861-921): whether it has the profile option (which serves the loops' process-value kinds,
// 16536+) and how many control and cascade loops it has. No I/O.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace station::drivers::watlow_f4t {

struct F4tPartNumber {
  std::string text;       ///< the 15 characters, one per register from 16
  bool profiles = false;  ///< character 7 'D', 'E' or 'F'
  int loops = 1;          ///< control loops (character 12)
  int cascades = 0;       ///< cascade loops (character 12 '6'..'C'): other registers, refused
};

/// Parses the part-number registers (one character each; non-printable ones dropped). A
/// character 12 the source does not list reads as one loop, as the source defaults.
F4tPartNumber parse_part_number(std::span<const std::uint16_t> words);

}  // namespace station::drivers::watlow_f4t
