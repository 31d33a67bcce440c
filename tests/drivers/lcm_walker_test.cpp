#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "romo/drivers/lcm_walker.hpp"
#include "romo/drivers/recording.hpp"
#include "romo_lcm/stereo_frame_t.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

TEST(LcmWalkerTest, CountMustFitTheBytesLeft) {
  const std::vector<std::uint8_t> bytes = {0, 0, 0, 2, 'a', 'b', 'c', 'd'};
  std::int32_t n = -1;
  LcmWalker fits(bytes.data(), bytes.size());
  EXPECT_TRUE(fits.Count(2, &n, "n"));  // 2 x 2 bytes in the 4 left
  EXPECT_EQ(n, 2);
  LcmWalker too_big(bytes.data(), bytes.size());
  EXPECT_FALSE(too_big.Count(3, &n, "n"));  // 2 x 3 bytes do not fit
  EXPECT_EQ(too_big.Reason("t"), "t.n = 2 does not fit a 8-byte message");
  EXPECT_FALSE(too_big.Skip(0));  // a failed walk stays failed
}

TEST(LcmWalkerTest, NegativeCountsZeroStringsAndTruncationFail) {
  const std::vector<std::uint8_t> negative = {0xff, 0xff, 0xff, 0xfe};
  std::int32_t n = 0;
  LcmWalker w(negative.data(), negative.size());
  EXPECT_FALSE(w.Count(1, &n, "count"));
  EXPECT_EQ(w.Reason("t"), "t.count = -2 does not fit a 4-byte message");
  const std::vector<std::uint8_t> empty_string = {0, 0, 0, 0};
  EXPECT_FALSE(LcmWalker(empty_string.data(), empty_string.size()).String("name"));
  LcmWalker short_input(negative.data(), negative.size());
  EXPECT_FALSE(short_input.Skip(5));
  EXPECT_EQ(short_input.Reason("t"), "t: truncated (4 bytes)");
  EXPECT_FALSE(LcmWalker(nullptr, 100).Skip(1));
  // "a\0b" with its terminator: LCM would encode it back as "a" (found by fuzz_lcm_planning).
  const std::vector<std::uint8_t> nul_inside = {0, 0, 0, 4, 'a', 0, 'b', 0};
  LcmWalker with_nul(nul_inside.data(), nul_inside.size());
  EXPECT_FALSE(with_nul.String("name"));
  EXPECT_EQ(with_nul.Reason("t"), "t.name: NUL at byte 1 inside the text");
  const std::vector<std::uint8_t> plain = {0, 0, 0, 3, 'a', 'b', 0};
  EXPECT_TRUE(LcmWalker(plain.data(), plain.size()).String("name"));
}

TEST(LcmWalkerTest, StereoFrameWithAnImpossibleImageSizeIsDroppedWithItsReason) {
  romo_lcm::stereo_frame_t msg;
  msg.rig_id = 0;
  for (romo_lcm::image_t* image : {&msg.left, &msg.right}) {
    image->camera_id = "cam";
    image->width = 4;
    image->height = 2;
    image->stride = 4;
    image->size = 8;
    image->data.assign(8, 7);
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  ASSERT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  // left.size: after hash, stamp, sequence, rig_id (28 bytes), the image's stamp and sequence
  // (16), camera_id (4 + 4), width, height, stride, format, encoding (14).
  constexpr std::size_t kLeftSizeOffset = 28 + 16 + 8 + 14;
  ASSERT_EQ(bytes[kLeftSizeOffset + 3], 8);
  for (int i = 0; i < 4; ++i) bytes[kLeftSizeOffset + i] = i == 0 ? 0x7f : 0xff;  // 2^31 - 1

  test::ScratchDir dir;
  const std::string path = dir / "huge.lcmlog";
  {
    LogWriter writer(path);
    writer.WriteRaw(StereoChannel(0), 1'000'000'000, bytes.data(), bytes.size());
  }
  LogReader reader(path);
  while (reader.Next()) {
  }
  const auto events = reader.status().events;
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].find("romo_lcm.stereo_frame_t.size = 2147483647 does not fit a " +
                           std::to_string(bytes.size()) + "-byte message"),
            std::string::npos)
      << events[0];
}

}  // namespace
}  // namespace romo::drivers
