// Camera buffers to romo images: Mono copies bit-exact, Bayer mosaics demosaic to the right colour.
#include <array>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/drivers/gige.hpp"

namespace romo::drivers {
namespace {

// A uniform colour mosaicked with the pattern whose top-left 2x2 cell is @p cell (0 R, 1 G, 2 B).
std::vector<std::uint8_t> Mosaic(int width, int height, std::array<int, 4> cell,
                                 std::array<std::uint8_t, 3> rgb) {
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(width) * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) raw[y * width + x] = rgb[cell[(y % 2) * 2 + (x % 2)]];
  }
  return raw;
}

TEST(GigeConvertTest, BayerPatternsGiveTheMosaickedColour) {
  constexpr int kWidth = 16, kHeight = 12;
  const std::array<std::uint8_t, 3> kColour = {200, 90, 30};
  // Demosaicing a uniform colour is exact away from the border; 1 grey level covers rounding.
  constexpr int kToleranceLevels = 1;
  const struct {
    GigePixelFormat format;
    std::array<int, 4> cell;
  } cases[] = {
      {GigePixelFormat::kBayerRG8, {0, 1, 1, 2}},
      {GigePixelFormat::kBayerGR8, {1, 0, 2, 1}},
      {GigePixelFormat::kBayerGB8, {1, 2, 0, 1}},
      {GigePixelFormat::kBayerBG8, {2, 1, 1, 0}},
  };
  for (const auto& c : cases) {
    const auto raw = Mosaic(kWidth, kHeight, c.cell, kColour);
    const Image image = ConvertGigeImage(raw.data(), raw.size(), kWidth, kHeight, c.format);
    ASSERT_EQ(image.format, PixelFormat::kRgb8);
    for (int y = 2; y < kHeight - 2; ++y) {
      for (int x = 2; x < kWidth - 2; ++x) {
        for (int ch = 0; ch < 3; ++ch) {
          ASSERT_NEAR(image.row(y)[3 * x + ch], kColour[ch], kToleranceLevels)
              << ToString(c.format) << " at " << x << "," << y << " channel " << ch;
        }
      }
    }
  }
}

TEST(GigeConvertTest, MonoTwelveKeepsSampleValues) {
  constexpr int kWidth = 5, kHeight = 3;  // odd width on purpose
  std::vector<std::uint16_t> samples(kWidth * kHeight);
  for (std::size_t i = 0; i < samples.size(); ++i) samples[i] = static_cast<std::uint16_t>(i * 273 % 4096);
  const Image image = ConvertGigeImage(reinterpret_cast<const std::uint8_t*>(samples.data()),
                                       samples.size() * 2, kWidth, kHeight, GigePixelFormat::kMono12);
  ASSERT_EQ(image.format, PixelFormat::kMono16);
  EXPECT_EQ(std::memcmp(image.data.data(), samples.data(), samples.size() * 2), 0);
}

TEST(GigeConvertTest, ShortBufferIsAnError) {
  std::vector<std::uint8_t> raw(10);
  EXPECT_THROW(ConvertGigeImage(raw.data(), raw.size(), 4, 4, GigePixelFormat::kMono8), Error);
}

}  // namespace
}  // namespace romo::drivers
