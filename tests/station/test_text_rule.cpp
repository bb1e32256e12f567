// Issue 34 point 10: one text rule where text enters (part files here; the configuration in
// test_config.cpp, the CLI in test_bad_options.cpp, the API in tests/web), and the block's
// checksum text made injective (gyro_tc.h, gyro_tc_canonical) while every text an earlier station
// wrote for a block it can represent stays the same bytes.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "station/parts/part_file.hpp"
#include "station/release/gyro_tc.h"

namespace {

std::string part_error(const std::string& text) {
  try {
    station::parse_part_file(text, "parts.toml");
  } catch (const station::InputError& e) {
    return e.what();
  }
  return {};
}

gyro_tc_block block_of(const char* serial, const char* part) {
  gyro_tc_block b{};
  b.serial = serial;
  b.part_number = part;
  b.fit_id = 7;
  b.released = 1;
  b.t_ref_c = 25;
  b.t_min_c = -40;
  b.t_max_c = 85;
  b.grad_min_c = -1;
  b.grad_max_c = 1;
  b.b0_dph = 0.125;
  b.k_dph[0] = 1e-3;
  b.k0_dph_per_c = -0.02;
  return b;
}

std::string canonical(const gyro_tc_block& b) {
  char text[GYRO_TC_CANONICAL_MAX];
  const int n = gyro_tc_canonical(&b, text, sizeof text);
  return n < 0 ? std::string("(does not fit)") : std::string(text, static_cast<std::size_t>(n));
}

}  // namespace

TEST(TextRule, PartNumbersAreIdentifiersAndDescriptionsNotes) {
  EXPECT_EQ(part_error("[part.\"GX-200/A\"]\ndescription = \"Jürgen's part, 5 °C\"\n"), "");
  EXPECT_NE(part_error("[part.\"GX\\u202E1\"]\n").find("U+202E at character 3 (byte 2)"),
            std::string::npos)
      << part_error("[part.\"GX\\u202E1\"]\n");
  EXPECT_NE(part_error("[part.\"=SUM(A1)\"]\n").find("U+003D at character 1"), std::string::npos)
      << part_error("[part.\"=SUM(A1)\"]\n");
  const std::string note = "[part.\"GX-1\"]\ndescription = \"ok\\u2067hidden\"\n";
  EXPECT_NE(part_error(note).find("parts.toml:2: key 'part.GX-1.description': U+2067 at "
                                  "character 3 (byte 2) is a bidirectional control"),
            std::string::npos)
      << part_error(note);
}

// The collision of issue 34: serial "X;part=Y" with no part and serial "X" with part "Y;part="
// wrote the same canonical text, so one checksum covered two different blocks.
TEST(TextRule, CanonicalTextTellsEverySerialAndPartApartAndKeepsVersion2sTexts) {
  const std::string a = canonical(block_of("X;part=Y", ""));
  const std::string b = canonical(block_of("X", "Y;part="));
  EXPECT_NE(a, b);
  EXPECT_EQ(a.rfind("gyro_tc/3;serial=X%3Bpart=Y;part=;fit=7;", 0), 0u) << a;
  EXPECT_EQ(b.rfind("gyro_tc/3;serial=X;part=Y%3Bpart=;fit=7;", 0), 0u) << b;
  // The escape character is escaped too: "%3B" given as text is not ";".
  EXPECT_NE(canonical(block_of("A%3BB", "")), canonical(block_of("A;B", "")));
  EXPECT_NE(canonical(block_of("A;", "B")), canonical(block_of("A", ";B")));
  // Released blocks keep their checksums: a block whose strings hold neither ';' nor '%' has
  // version 2's text, byte for byte (the format every earlier gyro_tc.h wrote).
  const gyro_tc_block o = block_of("RLG-2311-0043", "GX-200");
  char v2[GYRO_TC_CANONICAL_MAX];
  int len = std::snprintf(v2, sizeof v2, "gyro_tc/2;serial=%s;part=%s;fit=%lld;released=%d",
                          o.serial, o.part_number, o.fit_id, o.released);
  const double v[] = {o.t_ref_c,  o.t_min_c,  o.t_max_c,  o.grad_min_c, o.grad_max_c,  o.b0_dph,
                      o.k_dph[0], o.k_dph[1], o.k_dph[2], o.k_dph[3],   o.k0_dph_per_c};
  const char* key[] = {"t_ref_c", "t_min_c", "t_max_c", "grad_min_c", "grad_max_c", "b0_dph",
                       "k1",      "k2",      "k3",      "k4",         "k0"};
  for (int i = 0; i < 11; ++i)
    len += std::snprintf(v2 + len, sizeof v2 - static_cast<std::size_t>(len), ";%s=%.17g", key[i],
                         v[i]);
  EXPECT_EQ(canonical(o), std::string(v2, static_cast<std::size_t>(len)));
  // A text that does not fit is refused, escaped or not.
  char small[40];
  EXPECT_EQ(gyro_tc_canonical(&o, small, sizeof small), -1);
  const gyro_tc_block e = block_of(";;;;;;;;;;;;;;", "");
  EXPECT_EQ(gyro_tc_canonical(&e, small, sizeof small), -1);
}
