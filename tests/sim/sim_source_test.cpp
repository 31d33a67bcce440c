// The sim:// frame source: what a frame set holds, the calibration it reports, determinism
// across thread counts, and clear errors for bad parameters.
#include "romo/sim/sim_source.hpp"

#include <gtest/gtest.h>

#include "romo/core/check.hpp"

namespace romo::sim {
namespace {

std::string ErrorOf(const std::string& uri) {
  RegisterSimSource();
  try {
    drivers::OpenSource(uri);
  } catch (const romo::Error& e) {
    return e.what();
  }
  return "";
}

TEST(SimSourceTest, BadParametersGetClearErrors) {
  const struct {
    const char* uri;
    const char* expected;  // the message names the offending value
  } cases[] = {
      {"sim://carpark?frames=2", "unknown simulator scene 'carpark'"},
      {"sim://parking?frames=0", "frames = 0"},
      {"sim://parking?frames=-3", "frames = -3"},
      {"sim://parking?frames=abc", "'frames=abc' is not an integer"},
      {"sim://parking?scale=0", "scale"},
      {"sim://parking?scale=7", "scale"},
      {"sim://parking?seeed=3", "unknown key 'seeed'"},
      {"sim://parking?frames", "not key=value"},
      {"sim:/parking", "malformed source URI"},
      {"sim://parking?aa=9", "samples_per_axis = 9"},
      {"sim://parking?aa=4294967298", "'aa=4294967298' is outside"},  // was narrowed to 2
      {"sim://parking?threads=0", "'threads=0' is outside 1..256"},
      {"sim://parking?rate_hz=inf", "'rate_hz=inf' is not a finite number"},
      {"sim://parking?depth=yes", "'depth=yes' is not 0 or 1"},
      {"sim://parking?calib=/nonexistent/cal.yaml", "/nonexistent/cal.yaml"},
  };
  for (const auto& c : cases) {
    const std::string message = ErrorOf(c.uri);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << c.uri << " gave: '" << message << "'";
  }
}

TEST(SimSourceTest, DeliversSixRigsVehicleStateAndGnssWithMatchingCalibration) {
  RegisterSimSource();
  auto source = drivers::OpenSource("sim://parking?seed=3&frames=2&scale=0.25&aa=1");
  const drivers::Calibration* cal = source->calibration();
  ASSERT_NE(cal, nullptr);
  ASSERT_EQ(cal->rigs.size(), 6u);
  const drivers::Calibration full = drivers::Calibration::Load(drivers::SampleCalibrationPath());
  int count = 0;
  std::int64_t last_stamp = 0;
  while (auto set = source->Next()) {
    ASSERT_EQ(set->stereo.size(), 6u);
    for (std::size_t r = 0; r < 6; ++r) {
      const auto& f = set->stereo[r];
      const auto& rig = cal->rigs[r];
      EXPECT_EQ(f.rig_id, rig.rig_id);
      EXPECT_EQ(f.left.image.width, rig.width_px);
      EXPECT_EQ(f.left.image.height, rig.height_px);
      EXPECT_EQ(f.right.image.width, rig.width_px);
      EXPECT_EQ(f.left.image.format, drivers::PixelFormat::kMono8);
      EXPECT_EQ(f.left.stamp_ns, set->stamp_ns);
      // Quarter scale: 782x582 -> 196x146 (rounded), focal length scaled by the same ratio.
      EXPECT_EQ(rig.width_px, 196);
      EXPECT_EQ(rig.height_px, 146);
      EXPECT_NEAR(rig.left.K(0, 0), full.rigs[r].left.K(0, 0) * 196.0 / 782.0, 1e-9);
      EXPECT_NEAR(rig.left.K(0, 2), (full.rigs[r].left.K(0, 2) + 0.5) * 196.0 / 782.0 - 0.5, 1e-9);
      EXPECT_EQ(rig.left.distortion, full.rigs[r].left.distortion);
    }
    ASSERT_TRUE(set->vehicle.has_value());
    ASSERT_TRUE(set->gnss.has_value());
    EXPECT_TRUE(set->gnss->valid);
    EXPECT_NEAR(set->gnss->latitude_deg, 48.08, 0.01);
    if (count > 0) {
      EXPECT_EQ(set->stamp_ns - last_stamp, 100000000);  // 10 Hz
    }
    last_stamp = set->stamp_ns;
    ++count;
  }
  EXPECT_EQ(count, 2);
}

TEST(SimSourceTest, ImagesAreIdenticalForOneAndTwoThreadsAndDependOnTheSeed) {
  auto render = [](const std::string& uri) {
    SimSource s(SimParams::FromUri(drivers::Uri::Parse(uri)));
    return *s.Next();
  };
  const auto a = render("sim://parking?seed=5&frames=1&first=30&scale=0.25&threads=1");
  const auto b = render("sim://parking?seed=5&frames=1&first=30&scale=0.25&threads=2");
  const auto c = render("sim://parking?seed=6&frames=1&first=30&scale=0.25&threads=2");
  for (std::size_t r = 0; r < a.stereo.size(); ++r) {
    EXPECT_EQ(a.stereo[r].left.image.data, b.stereo[r].left.image.data) << "rig " << r;
    EXPECT_EQ(a.stereo[r].right.image.data, b.stereo[r].right.image.data) << "rig " << r;
    EXPECT_NE(a.stereo[r].left.image.data, c.stereo[r].left.image.data) << "rig " << r;
  }
}

TEST(SimSourceTest, ImagesAreTexturedEverywhereBelowTheHorizon) {
  // SGM needs texture: the local grey-value spread in 9x9 windows below the horizon must exceed
  // the sensor noise alone in nearly every window.
  constexpr double kMinStdDev = 3.0;          // grey levels (noise alone: 2)
  constexpr double kMinTexturedFraction = 0.97;
  SimSource s(SimParams::FromUri(drivers::Uri::Parse("sim://parking?frames=1&first=50&scale=0.5")));
  const auto set = *s.Next();
  for (const auto& f : set.stereo) {
    const drivers::Image& im = f.left.image;
    int windows = 0, textured = 0;
    // The lower 55% of the image is ground or objects (cameras pitched 15 degrees down).
    for (int y0 = im.height * 45 / 100; y0 + 9 <= im.height; y0 += 9) {
      for (int x0 = 0; x0 + 9 <= im.width; x0 += 9) {
        double sum = 0, sum2 = 0;
        for (int y = y0; y < y0 + 9; ++y) {
          for (int x = x0; x < x0 + 9; ++x) {
            const double v = im.row(y)[x];
            sum += v;
            sum2 += v * v;
          }
        }
        const double mean = sum / 81, var = sum2 / 81 - mean * mean;
        ++windows;
        textured += std::sqrt(std::max(0.0, var)) > kMinStdDev;
      }
    }
    EXPECT_GE(static_cast<double>(textured) / windows, kMinTexturedFraction) << "rig " << f.rig_id;
  }
}

}  // namespace
}  // namespace romo::sim
