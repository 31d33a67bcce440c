#include <cstring>
#include <functional>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "romo/core/check.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frame_source.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

using ::romo::test::ErrorOf;

// Stamps come from text seconds or from index / 30 Hz: 1 us covers double rounding.
constexpr std::int64_t kStampToleranceNs = 1000;

std::vector<FrameSet> ReadAll(FrameSource* source) {
  std::vector<FrameSet> sets;
  while (auto set = source->Next()) sets.push_back(std::move(*set));
  return sets;
}

// The frame holds exactly the file's pixels (depth unchanged, colour as RGB).
void ExpectMatchesFiles(const RgbdFrame& frame, const std::string& rgb_file,
                        const std::string& depth_file) {
  const cv::Mat depth = cv::imread(depth_file, cv::IMREAD_UNCHANGED);
  const cv::Mat bgr = cv::imread(rgb_file, cv::IMREAD_COLOR);
  ASSERT_EQ(frame.depth.width, depth.cols);
  ASSERT_EQ(frame.depth.height, depth.rows);
  ASSERT_EQ(frame.depth.format, PixelFormat::kMono16);
  for (int y = 0; y < depth.rows; ++y) {
    ASSERT_EQ(0, std::memcmp(frame.depth.row(y), depth.ptr(y), static_cast<std::size_t>(depth.cols) * 2));
  }
  ASSERT_EQ(frame.rgb.format, PixelFormat::kRgb8);
  ASSERT_EQ(frame.rgb.width, bgr.cols);
  for (int y = 0; y < bgr.rows; y += 37) {
    for (int x = 0; x < bgr.cols; x += 41) {
      const auto& p = bgr.at<cv::Vec3b>(y, x);
      const std::uint8_t* q = frame.rgb.row(y) + 3 * x;
      ASSERT_EQ(q[0], p[2]);
      ASSERT_EQ(q[1], p[1]);
      ASSERT_EQ(q[2], p[0]);
    }
  }
}

TEST(RgbdSourceTest, TumPairFolderGivesBothFramesAtScale5000) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/tum_pair");
  const std::string dir = test::SharedData("rgbd/tum_pair");
  auto source = OpenSource("rgbd://" + dir);
  const auto sets = ReadAll(source.get());
  ASSERT_EQ(sets.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(sets[i].rgbd);
    EXPECT_EQ(sets[i].sequence, i);
    EXPECT_DOUBLE_EQ(sets[i].rgbd->depth_scale_m, 1.0 / 5000.0);
    ExpectMatchesFiles(*sets[i].rgbd, dir + "/" + std::to_string(i + 1) + ".png",
                       dir + "/" + std::to_string(i + 1) + "_depth.png");
  }
}

TEST(RgbdSourceTest, ColorAndDepthFoldersPairByStemInMillimetres) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/kinect_seq");
  const std::string dir = test::SharedData("rgbd/kinect_seq");
  auto source = OpenSource("rgbd://" + dir + "?rate_hz=10");
  const auto sets = ReadAll(source.get());
  ASSERT_EQ(sets.size(), 5u);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    EXPECT_DOUBLE_EQ(sets[i].rgbd->depth_scale_m, 0.001);
    EXPECT_NEAR(sets[i].stamp_ns, static_cast<std::int64_t>(i) * 100'000'000, kStampToleranceNs);
  }
  ExpectMatchesFiles(*sets[4].rgbd, dir + "/color/5.png", dir + "/depth/5.pgm");
}

TEST(RgbdSourceTest, MatchFileLayoutAndDepthScaleOverride) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/primesense_seq");
  const std::string dir = test::SharedData("rgbd/primesense_seq");
  auto source = OpenSource("rgbd://" + dir + "?depth_scale=1000");
  const auto sets = ReadAll(source.get());
  ASSERT_EQ(sets.size(), 5u);
  ExpectMatchesFiles(*sets[2].rgbd, dir + "/color/00002.jpg", dir + "/depth/00002.png");
  auto scaled = OpenSource("rgbd://" + dir + "?depth_scale=4000");
  EXPECT_DOUBLE_EQ(scaled->Next()->rgbd->depth_scale_m, 1.0 / 4000.0);
}

TEST(RgbdSourceTest, TumTextFilesPairByNearestTimestampWithinTolerance) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/tum_pair");
  const std::string data = test::SharedData("rgbd/tum_pair");
  test::ScratchDir dir;
  ASSERT_EQ(::mkdir((dir / "rgb").c_str(), 0755), 0);
  ASSERT_EQ(::mkdir((dir / "depth").c_str(), 0755), 0);
  for (const char* name : {"a", "b", "c"}) {
    ASSERT_EQ(::symlink((data + "/1.png").c_str(), (dir / "rgb/" + name + ".png").c_str()), 0);
    ASSERT_EQ(::symlink((data + "/1_depth.png").c_str(), (dir / "depth/" + name + ".png").c_str()), 0);
  }
  // 30 Hz colour; depth 5 and 7 ms off for the first two, the third 134 ms away (> 20 ms).
  test::WriteFile(dir / "rgb.txt", "# timestamp filename\n1.000 rgb/a.png\n1.033 rgb/b.png\n1.066 rgb/c.png\n");
  test::WriteFile(dir / "depth.txt", "# timestamp filename\n1.005 depth/a.png\n1.040 depth/b.png\n1.200 depth/c.png\n");
  auto source = OpenSource("rgbd://" + dir.path());
  const auto sets = ReadAll(source.get());
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_NEAR(sets[0].stamp_ns, 1'000'000'000, kStampToleranceNs);
  EXPECT_NEAR(sets[1].stamp_ns, 1'033'000'000, kStampToleranceNs);
  EXPECT_DOUBLE_EQ(sets[0].rgbd->depth_scale_m, 1.0 / 5000.0);
  EXPECT_EQ(source->status().cameras.at(0).unpaired, 2u);  // colour c and depth c

  auto wide = OpenSource("rgbd://" + dir.path() + "?max_dt_s=0.2");
  EXPECT_EQ(ReadAll(wide.get()).size(), 3u);

  test::WriteFile(dir / "associations.txt", "1.000 rgb/a.png 1.005 depth/a.png\n1.066 rgb/c.png 1.2 depth/c.png\n");
  auto assoc = OpenSource("rgbd://" + dir.path());
  EXPECT_EQ(ReadAll(assoc.get()).size(), 2u);
}

TEST(RgbdSourceTest, CameraJsonInTheFolderGivesTheIntrinsics) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/primesense_seq");
  ROMO_REQUIRE_SHARED_DATA("rgbd/kinect_seq");
  // primesense_seq/camera_primesense.json: Open3D's layout, K column-major.
  auto source = OpenSource("rgbd://" + test::SharedData("rgbd/primesense_seq"));
  const Calibration* calib = source->calibration();
  ASSERT_NE(calib, nullptr);
  ASSERT_EQ(calib->rigs.size(), 1u);
  const RigCalibration& rig = calib->rigs.front();
  EXPECT_EQ(rig.width_px, 640);
  EXPECT_EQ(rig.height_px, 480);
  EXPECT_EQ(rig.left.K(0, 0), 525.0);
  EXPECT_EQ(rig.left.K(1, 1), 525.0);
  EXPECT_EQ(rig.left.K(0, 2), 319.5);
  EXPECT_EQ(rig.left.K(1, 2), 239.5);
  EXPECT_NO_THROW(calib->Validate("primesense_seq"));  // recordings carry it
  bool reported = false;
  for (const auto& e : source->status().events) reported |= e.find("camera_primesense.json") != std::string::npos;
  EXPECT_TRUE(reported);
  EXPECT_EQ(ReadAll(source.get()).size(), 5u);
  // A folder without one carries no calibration.
  EXPECT_EQ(OpenSource("rgbd://" + test::SharedData("rgbd/kinect_seq"))->calibration(), nullptr);
}

TEST(RgbdSourceTest, BadCameraJsonGivesClearErrors) {
  ROMO_REQUIRE_SHARED_DATA("rgbd/tum_pair");
  const std::string data = test::SharedData("rgbd/tum_pair");
  test::ScratchDir dir;
  for (const char* name : {"1.png", "1_depth.png"}) {
    ASSERT_EQ(::symlink((data + "/" + name).c_str(), (dir / name).c_str()), 0);
  }
  const std::string uri = "rgbd://" + dir.path();
  test::WriteFile(dir / "camera.json", R"({"width": 640, "height": 480, "intrinsic_matrix": [520, 0, 0, 0, 521, 0, 325]})");
  std::string e = ErrorOf([&] { OpenSource(uri); });
  EXPECT_NE(e.find("camera.json: \"intrinsic_matrix\" must hold 9 numbers (column-major 3x3), got 7"),
            std::string::npos) << e;
  test::WriteFile(dir / "camera.json", R"({"height": 480, "intrinsic_matrix": [520, 0, 0, 0, 521, 0, 325, 249, 1]})");
  e = ErrorOf([&] { OpenSource(uri); });
  EXPECT_NE(e.find("camera JSON without \"width\""), std::string::npos) << e;
  test::WriteFile(dir / "camera.json", R"({"width": 640, "height": 480, "intrinsic_matrix": [-520, 0, 0, 0, 521, 0, 325, 249, 1]})");
  e = ErrorOf([&] { OpenSource(uri); });
  EXPECT_NE(e.find("is not a pinhole K"), std::string::npos) << e;
  // Valid, but for other images than the folder's 640x480 ones: the first frame says so.
  test::WriteFile(dir / "camera.json", R"({"width": 320, "height": 240, "intrinsic_matrix": [260, 0, 0, 0, 260, 0, 160, 120, 1]})");
  auto source = OpenSource(uri);
  e = ErrorOf([&] { source->Next(); });
  EXPECT_NE(e.find("640x480 depth image, but " + (dir / "camera.json") + " is for 320x240"), std::string::npos) << e;
}

TEST(RgbdSourceTest, BadFoldersAndFilesGiveClearErrors) {
  test::ScratchDir dir;
  EXPECT_EQ(ErrorOf([&] { OpenSource("rgbd://" + (dir / "none")); }),
            dir / "none" + ": RGB-D folder not found");
  EXPECT_NE(ErrorOf([&] { OpenSource("rgbd://" + dir.path()); }).find("no RGB-D pairs found"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { OpenSource("rgbd://" + dir.path() + "?scale=3"); }).find("unknown option 'scale'"),
            std::string::npos);

  // An 8-bit "depth" image is rejected by name when it is read.
  const cv::Mat grey(4, 6, CV_8UC1, cv::Scalar(7));
  const cv::Mat colour(4, 6, CV_8UC3, cv::Scalar(1, 2, 3));
  ASSERT_TRUE(cv::imwrite(dir / "1.png", colour));
  ASSERT_TRUE(cv::imwrite(dir / "1_depth.png", grey));
  auto source = OpenSource("rgbd://" + dir.path());
  EXPECT_NE(ErrorOf([&] { source->Next(); }).find(dir / "1_depth.png" + ": depth image must be 16-bit"),
            std::string::npos);

  test::WriteFile(dir / "rgb.txt", "1.0 rgb/x.png\nnot a line\n");
  test::WriteFile(dir / "depth.txt", "1.0 depth/x.png\n");
  EXPECT_NE(ErrorOf([&] { OpenSource("rgbd://" + dir.path()); }).find(dir / "rgb.txt:2: expected 'timestamp file'"),
            std::string::npos);
  test::WriteFile(dir / "rgb.txt", "1.0 rgb/x.png\n");
  EXPECT_NE(ErrorOf([&] { OpenSource("rgbd://" + dir.path()); }).find("rgb/x.png not found"),
            std::string::npos);
  // A stamp no int64 nanosecond count holds is named (llround would have returned garbage).
  test::WriteFile(dir / "depth.txt", "1.0 depth/x.png\n2e10 depth/y.png\n");
  EXPECT_NE(ErrorOf([&] { OpenSource("rgbd://" + dir.path()); }).find(dir / "depth.txt:2: timestamp"),
            std::string::npos);
  test::WriteFile(dir / "associations.txt", "1e300 rgb/a.png 1 depth/a.png\n");
  EXPECT_NE(ErrorOf([&] { OpenSource("rgbd://" + dir.path()); })
                .find(dir / "associations.txt:1: timestamp 1000000"),
            std::string::npos);
}

}  // namespace
}  // namespace romo::drivers
