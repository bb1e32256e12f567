// Counter-board CAN codec: round trips, byte layout and every decode error.
#include <gtest/gtest.h>

#include "drivers/counters/counter_frames.hpp"

namespace c = station::drivers::counters;
using station::drivers::ErrorKind;

TEST(CanFrames, SyncRoundTrip) {
  const can_frame f = c::encode(c::SyncFrame{0xA5});
  EXPECT_EQ(f.can_id, 0x080u);
  EXPECT_EQ(f.can_dlc, 1);
  auto d = c::decode_sync(f);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.value().latch_seq, 0xA5);
}

TEST(CanFrames, StatusLayoutIsLittleEndian) {
  const can_frame f = c::encode(c::StatusFrame{3, 7, c::kFlagDitherFault, 0x11223344, 0x07});
  EXPECT_EQ(f.can_id, 0x183u);
  ASSERT_EQ(f.can_dlc, 8);
  const std::uint8_t want[8] = {7, 0x08, 0x44, 0x33, 0x22, 0x11, 0x07, 0};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], want[i]) << i;
  auto d = c::decode_status(f);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.value().node, 3);
  EXPECT_EQ(d.value().latch_seq, 7);
  EXPECT_EQ(d.value().flags, c::kFlagDitherFault);
  EXPECT_EQ(d.value().board_time_us, 0x11223344u);
  EXPECT_EQ(d.value().follows, 7);
}

TEST(CanFrames, CountsRoundTripExtremes) {
  const can_frame f = c::encode(c::CountsFrame{16, 0xFFFFFFFFu, 0x01020304u});
  EXPECT_EQ(f.can_id, 0x290u);
  EXPECT_EQ(f.data[4], 0x04);
  auto d = c::decode_counts(f);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.value().up, 0xFFFFFFFFu);
  EXPECT_EQ(d.value().down, 0x01020304u);
}

TEST(CanFrames, TempsRoundTripSignedAndDlcFollowsCount) {
  c::TempsFrame t{2, 3, {-4000, 7000, 2512, 0}};
  const can_frame f = c::encode(t);
  EXPECT_EQ(f.can_id, 0x382u);
  EXPECT_EQ(f.can_dlc, 6);
  auto d = c::decode_temps(f);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.value().count, 3);
  EXPECT_EQ(d.value().centi_c[0], -4000);
  EXPECT_EQ(d.value().centi_c[1], 7000);
  EXPECT_EQ(d.value().centi_c[2], 2512);
}

TEST(CanFrames, DischargeRoundTrip) {
  auto d = c::decode_discharge(c::encode(c::DischargeFrame{5, {612, 655}}));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.value().node, 5);
  EXPECT_EQ(d.value().leg_ua[0], 612u);
  EXPECT_EQ(d.value().leg_ua[1], 655u);
}

void expect_protocol(const station::drivers::Error& e, const char* needle) {
  EXPECT_EQ(e.kind, ErrorKind::protocol);
  EXPECT_NE(e.message.find(needle), std::string::npos) << e.message;
}

TEST(CanFrames, BadDlcIsNamed) {
  can_frame f = c::encode(c::CountsFrame{1, 1, 2});
  f.can_dlc = 7;
  expect_protocol(c::decode_counts(f).error(), "bad DLC");
  can_frame s = c::encode(c::SyncFrame{1});
  s.can_dlc = 0;
  expect_protocol(c::decode_sync(s).error(), "bad DLC");
  can_frame t = c::encode(c::TempsFrame{1, 2, {}});
  t.can_dlc = 3;
  expect_protocol(c::decode_temps(t).error(), "bad DLC");
  t.can_dlc = 0;
  expect_protocol(c::decode_temps(t).error(), "bad DLC");
}

TEST(CanFrames, UnknownIdAndNodeOutOfRange) {
  can_frame f = c::encode(c::CountsFrame{1, 0, 0});
  std::uint8_t node = 0;
  f.can_id = 0x701;
  expect_protocol(c::classify(f, &node).error(), "unknown ID");
  f.can_id = 0x280 + 17;
  expect_protocol(c::classify(f, &node).error(), "node out of range");
  expect_protocol(c::decode_counts(f).error(), "node out of range");
  f.can_id = 0x280;
  expect_protocol(c::decode_counts(f).error(), "node out of range");
  f.can_id = 0x181;
  expect_protocol(c::decode_counts(f).error(), "unexpected function code");
  f.can_id = 0x281 | CAN_EFF_FLAG;
  expect_protocol(c::classify(f, &node).error(), "extended");
}

// Found by fuzz_can_frames: 0x02000181 without CAN_EFF_FLAG was read as STATUS of node 1 (the
// bits above 11 ignored), so a frame the codec accepted could not be re-encoded. A standard ID
// has 11 bits; anything above them is a malformed frame, rejected by every decoder.
TEST(CanFrames, StandardIdWithBitsAbove11IsRejected) {
  std::uint8_t node = 0;
  for (can_frame f : {c::encode(c::StatusFrame{1, 0, 0, 0, 0}), c::encode(c::CountsFrame{1, 0, 0}),
                      c::encode(c::SyncFrame{0})}) {
    f.can_id |= 0x02000000;
    expect_protocol(c::classify(f, &node).error(), "ID bits above 11");
    EXPECT_FALSE(c::decode_status(f).ok());
    EXPECT_FALSE(c::decode_counts(f).ok());
    EXPECT_FALSE(c::decode_sync(f).ok());
  }
}

TEST(CanFrames, ClassifyNamesKindAndNode) {
  std::uint8_t node = 0;
  auto k = c::classify(c::encode(c::DischargeFrame{9, {}}), &node);
  ASSERT_TRUE(k.ok());
  EXPECT_EQ(k.value(), c::FrameKind::discharge);
  EXPECT_EQ(node, 9);
  k = c::classify(c::encode(c::SyncFrame{0}), &node);
  ASSERT_TRUE(k.ok());
  EXPECT_EQ(k.value(), c::FrameKind::sync);
}

TEST(CanFrames, FiltersAcceptBoardFramesOnly) {
  const auto filters = c::board_frame_filters();
  auto accepted = [&](canid_t id) {
    for (const auto& fl : filters)
      if ((id & fl.can_mask) == (fl.can_id & fl.can_mask)) return true;
    return false;
  };
  EXPECT_TRUE(accepted(0x181));
  EXPECT_TRUE(accepted(0x290));
  EXPECT_TRUE(accepted(0x385));
  EXPECT_TRUE(accepted(0x48F));
  EXPECT_FALSE(accepted(0x080));
  EXPECT_FALSE(accepted(0x701));
}
