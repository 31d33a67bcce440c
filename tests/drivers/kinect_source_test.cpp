// kinect:// through the real libfreenect. No Kinect is attached to the test machines, so the
// no-device path is what runs here; recorded sessions replay through fakenect (same code).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/recording.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

std::string ErrorOf(const std::string& uri) {
  try {
    OpenSource(uri);
  } catch (const romo::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(KinectSourceTest, NoDeviceGivesClearError) {
  EXPECT_NE(ErrorOf("kinect://0").find("no Kinect found at index 0"), std::string::npos)
      << ErrorOf("kinect://0");
  EXPECT_NE(ErrorOf("kinect://3").find("no Kinect found at index 3"), std::string::npos);
}

TEST(KinectSourceTest, BadIndexOrOptionsAreRejected) {
  EXPECT_NE(ErrorOf("kinect://front").find("Kinect index 'front' must be a number"), std::string::npos);
  EXPECT_NE(ErrorOf("kinect://-1").find("must be a number 0-63"), std::string::npos);
  EXPECT_NE(ErrorOf("kinect://0?fps=30").find("takes no options"), std::string::npos);
}

// A fakenect dump (the layout fakenect-record writes): INDEX.txt, d-<time>-<ts>.pgm with
// little-endian 11-bit raw depth, r-<time>-<ts>.ppm RGB. Raw 2047 (no return) on row 0,
// raw 600 elsewhere; colour (10 k, 20, 30) in frame k.
void WriteFakenectDump(const std::string& dir, int frames) {
  std::string index;
  for (int k = 0; k < frames; ++k) {
    char depth_name[64];
    char rgb_name[64];
    std::snprintf(depth_name, sizeof depth_name, "d-%.6f-%d.pgm", 1.7e9 + k / 30.0, 1000 + k);
    std::snprintf(rgb_name, sizeof rgb_name, "r-%.6f-%d.ppm", 1.7e9 + k / 30.0 + 0.001, 1000 + k);
    std::string depth = "P5 640 480 65535\n";
    for (int i = 0; i < 640 * 480; ++i) {
      const int raw = i < 640 ? 2047 : 600;
      depth += static_cast<char>(raw & 0xFF);
      depth += static_cast<char>(raw >> 8);
    }
    std::string rgb = "P6 640 480 255\n";
    for (int i = 0; i < 640 * 480; ++i) {
      rgb += static_cast<char>(10 * k);
      rgb += static_cast<char>(20);
      rgb += static_cast<char>(30);
    }
    test::WriteFile(dir + "/" + depth_name, depth);
    test::WriteFile(dir + "/" + rgb_name, rgb);
    index += std::string(depth_name) + "\n" + rgb_name + "\n";
  }
  test::WriteFile(dir + "/INDEX.txt", index);
}

// libfreenect's sync API would wait for the next frame forever once frames stop (an unplugged
// Kinect; here fakenect at the end of its dump): the source ends the stream, says why, and the
// recording keeps every frame that came.
TEST(KinectSourceTest, AStreamThatStopsEndsWithItsReasonAndKeepsItsFrames) {
  test::ScratchDir dir;
  constexpr int kDumpFrames = 3;
  WriteFakenectDump(dir.path(), kDumpFrames);
  const auto started = std::chrono::steady_clock::now();
  const auto result = test::RunShell("timeout 120 fakenect '" + dir.path() + "' '" + test::RomoBinary() +
                                     "' record --source kinect://0 --out '" + (dir / "k.lcmlog") + "' --frames 10");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
  // At most the source's 2 s frame timeout after the last frame, not the shell's 120 s.
  EXPECT_LT(seconds, 60.0);
  EXPECT_NE(result.err.find("kinect 0 stopped after "), std::string::npos) << result.err;
  LogReader reader(dir / "k.lcmlog");
  int count = 0;
  while (auto set = reader.Next()) {
    ASSERT_TRUE(set->rgbd);
    ++count;
  }
  // fakenect plays in real time: a slow reader may miss a frame, never gain one.
  EXPECT_GE(count, 1);
  EXPECT_LE(count, kDumpFrames);
}

TEST(KinectSourceTest, FakenectReplayRecordsThroughTheSameCode) {
  test::ScratchDir dir;
  // The dump holds more frames than are recorded: the stream ends only once it runs dry.
  WriteFakenectDump(dir.path(), 10);
  const std::string romo = test::RomoBinary();
  const auto result = test::RunShell("timeout 120 fakenect '" + dir.path() + "' '" + romo +
                                     "' record --source kinect://0 --out '" + (dir / "k.lcmlog") +
                                     "' --frames 3");
  ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
  LogReader reader(dir / "k.lcmlog");
  // The documented tangent fit for raw 600, in whole millimetres.
  const auto expected_mm =
      static_cast<std::uint16_t>(std::lround(0.1236 * std::tan(600 / 2842.5 + 1.1863) * 1000.0));
  int count = 0;
  while (auto set = reader.Next()) {
    ASSERT_TRUE(set->rgbd);
    const RgbdFrame& frame = *set->rgbd;
    ASSERT_EQ(frame.depth.width, 640);
    ASSERT_EQ(frame.rgb.height, 480);
    EXPECT_DOUBLE_EQ(frame.depth_scale_m, 0.001);
    const auto* depth = reinterpret_cast<const std::uint16_t*>(frame.depth.data.data());
    EXPECT_EQ(depth[5], 0);  // raw 2047: no return
    EXPECT_EQ(depth[640 * 240 + 320], expected_mm);
    EXPECT_EQ(frame.rgb.data[1], 20);
    EXPECT_EQ(frame.rgb.data[2], 30);
    ++count;
  }
  EXPECT_EQ(count, 3);
  // libfreenect reads no calibration: the recording carries the Kinect v1 defaults (640x480,
  // fx = fy = 525, c = (319.5, 239.5)), so romo manip needs no --intrinsics.
  const Calibration* calib = reader.calibration();
  ASSERT_NE(calib, nullptr);
  ASSERT_EQ(calib->rigs.size(), 1u);
  const Eigen::Matrix3d& K = calib->rigs.front().left.K;
  EXPECT_EQ(K(0, 0), 525.0);
  EXPECT_EQ(K(1, 1), 525.0);
  EXPECT_EQ(K(0, 2), 319.5);
  EXPECT_EQ(K(1, 2), 239.5);
  EXPECT_EQ(calib->rigs.front().width_px, 640);
}

}  // namespace
}  // namespace romo::drivers
