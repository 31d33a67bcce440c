// `romo sim` end to end: the recording it writes is byte-identical for 1 and 2 threads, reads
// back through log:// with calibration, 6 rigs and ground truth, `romo info` accepts it, and bad
// parameters exit non-zero with a clear message.
#include <cstdlib>

#include <gtest/gtest.h>

#include "romo/drivers/recording.hpp"
#include "romo/sim/ground_truth.hpp"
#include "test_support.hpp"

namespace romo::sim {
namespace {

constexpr const char* kSmallRun = "sim --scene parking --seed 11 --frames 2 --first 60 --scale 0.25";

TEST(SimCliTest, SameSeedSameBytesForOneAndTwoThreads) {
  test::ScratchDir dir;
  const auto a = test::RunRomo(std::string(kSmallRun) + " --threads 1 --out " + (dir / "a.lcmlog"));
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto b = test::RunRomo(std::string(kSmallRun) + " --threads 2 --out " + (dir / "b.lcmlog"));
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const std::string bytes_a = test::ReadFile(dir / "a.lcmlog");
  EXPECT_GT(bytes_a.size(), 12u * 196 * 146 * 2);  // 2 frames of 12 quarter-scale images
  EXPECT_TRUE(bytes_a == test::ReadFile(dir / "b.lcmlog")) << "recordings differ";
}

TEST(SimCliTest, RecordingReadsBackWithCalibrationRigsAndGroundTruth) {
  test::ScratchDir dir;
  const std::string path = dir / "run.lcmlog";
  const auto r = test::RunRomo(std::string(kSmallRun) + " --depth --out " + path);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  drivers::LogReader reader(path);
  ASSERT_NE(reader.calibration(), nullptr);
  EXPECT_EQ(reader.calibration()->rigs.size(), 6u);
  EXPECT_EQ(reader.calibration()->rigs[0].width_px, 196);
  int frames = 0, truths = 0, depths = 0;
  while (auto set = reader.Next()) {
    ++frames;
    EXPECT_EQ(set->stereo.size(), 6u);
    EXPECT_TRUE(set->vehicle.has_value());
    EXPECT_TRUE(set->gnss.has_value());
    for (const auto& e : reader.other_events()) {
      if (e.channel == kGroundTruthChannel) {
        const GroundTruth t = DecodeGroundTruth(e.data.data(), e.data.size(), path);
        EXPECT_EQ(t.seed, 11u);
        EXPECT_FALSE(t.objects.empty());
        EXPECT_EQ(t.bays.size(), 2u);
        ++truths;
      } else if (e.channel.rfind("ROMO_GT_DEPTH_RIG", 0) == 0) {
        const GtDepth d = DecodeGtDepth(e.data.data(), e.data.size(), path);
        EXPECT_EQ(d.width, 196);
        ++depths;
      }
    }
  }
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(truths, 2);
  EXPECT_EQ(depths, 12);
  const auto info = test::RunRomo("info " + path);
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("ROMO_GT_FRAME"), std::string::npos) << info.out;
}

TEST(SimCliTest, BadParametersExitNonZeroWithAClearMessage) {
  test::ScratchDir dir;
  const std::string out = " --out " + (dir / "x.lcmlog");
  const auto scene = test::RunRomo("sim --scene carpark --frames 1" + out);
  EXPECT_EQ(scene.exit_code, 2);
  EXPECT_NE(scene.err.find("unknown simulator scene 'carpark'"), std::string::npos) << scene.err;
  const auto frames = test::RunRomo("sim --scene parking --frames 0" + out);
  EXPECT_EQ(frames.exit_code, 2);
  EXPECT_NE(frames.err.find("frames = 0"), std::string::npos) << frames.err;
  const auto negative = test::RunRomo("sim --scene parking --frames -4" + out);
  EXPECT_EQ(negative.exit_code, 2);
  EXPECT_NE(negative.err.find("frames = -4"), std::string::npos) << negative.err;
  const auto scale = test::RunRomo("sim --scene parking --frames 1 --scale 0" + out);
  EXPECT_EQ(scale.exit_code, 2);
  EXPECT_NE(scale.err.find("scale"), std::string::npos) << scale.err;
}

}  // namespace
}  // namespace romo::sim
