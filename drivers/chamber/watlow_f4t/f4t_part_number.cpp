// F4T part number: the profile option and the loop counts (CCL process_controller:861-921).
#include "drivers/chamber/watlow_f4t/f4t_part_number.hpp"

#include "drivers/chamber/watlow_f4t/f4t_map.hpp"

namespace station::drivers::watlow_f4t {

F4tPartNumber parse_part_number(std::span<const std::uint16_t> words) {
  F4tPartNumber p;
  for (auto w : words)
    if (w >= 0x20 && w < 0x7f) p.text += static_cast<char>(w);
  if (p.text.size() > static_cast<std::size_t>(kPartProfilesChar)) {
    const char c = p.text[kPartProfilesChar];
    p.profiles = c == 'D' || c == 'E' || c == 'F';  // CCL :866-882
  }
  if (p.text.size() <= static_cast<std::size_t>(kPartLoopsChar)) return p;
  // CCL :884-916: '1'..'4' loops; '5' none; '6'..'9' one cascade with 0..3 loops; 'A'..'C' two
  // cascades with 0..2 loops.
  const char c = p.text[kPartLoopsChar];
  if (c >= '1' && c <= '4') {
    p.loops = c - '0';
  } else if (c == '5') {
    p.loops = 0;
  } else if (c >= '6' && c <= '9') {
    p.loops = c - '6', p.cascades = 1;
  } else if (c >= 'A' && c <= 'C') {
    p.loops = c - 'A', p.cascades = 2;
  }
  return p;
}

}  // namespace station::drivers::watlow_f4t
