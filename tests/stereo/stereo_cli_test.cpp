// `romo stereo` and `romo eval stereo` end to end through the built binary.
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "romo/stereo/pcd_io.hpp"
#include "romo/stereo/synthetic.hpp"
#include "test_support.hpp"

namespace romo::stereo {
namespace {

bool Contains(const std::string& s, const std::string& what) { return s.find(what) != std::string::npos; }

TEST(StereoCliTest, EvalStereoPrintsJsonForRomoAndOpenCv) {
  ROMO_REQUIRE_SHARED_DATA("middlebury/venus/im2.png");
  const std::string dir = test::SharedData("middlebury/venus/");
  const test::CommandResult r = test::RunRomo("eval stereo --left " + dir + "im2.png --right " + dir +
                                              "im6.png --gt " + dir + "disp2.png --gt-scale 8 --ndisp 32 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Contains(r.out, "\"scene\": \"venus\"")) << r.out;
  for (const char* key : {"bad1_all", "bad1_nonocc", "bad2_all", "bad2_nonocc", "rms_all", "density", "ms"}) {
    EXPECT_TRUE(Contains(r.out, std::string("\"") + key + "\": ")) << key;
  }
  EXPECT_TRUE(Contains(r.out, "\"romo\": {")) << r.out;
  EXPECT_TRUE(Contains(r.out, "\"opencv\": {")) << r.out;
  EXPECT_FALSE(Contains(r.out, "null")) << "venus has right ground truth: " << r.out;

  // tsukuba has no disp6.png: non-occluded figures are null.
  const std::string ts = test::SharedData("middlebury/tsukuba/");
  const test::CommandResult t = test::RunRomo("eval stereo --left " + ts + "im2.png --right " + ts +
                                              "im6.png --gt " + ts + "disp2.png --gt-scale 16 --ndisp 16 --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_TRUE(Contains(t.out, "\"bad1_nonocc\": null")) << t.out;
}

TEST(StereoCliTest, StereoWritesDisparityPictureAndCloud) {
  ROMO_REQUIRE_SHARED_DATA("kitti/stereo_pair/left.png");
  test::ScratchDir out;
  const std::string k = test::SharedData("kitti/stereo_pair/");
  const test::CommandResult r = test::RunRomo("stereo --left " + k + "left.png --right " + k +
                                              "right.png --focal 718.856 --baseline 0.573 --out " + out.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat disparity = cv::imread(out / "disparity.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(disparity.type(), CV_16UC1);
  EXPECT_EQ(disparity.cols, 1241);
  EXPECT_EQ(cv::imread(out / "disparity_color.png").channels(), 3);
  const PointCloud cloud = LoadPcd(out / "cloud.pcd");
  // A road scene: most of the image matches; all points within the default 40 m range.
  EXPECT_GT(cloud.size(), 100000u);
  for (Eigen::Index i = 0; i < cloud.xyz.cols(); ++i) ASSERT_LE(cloud.xyz.col(i).norm(), 40.f + 1e-3f);
}

TEST(StereoCliTest, StereoWithSampleCalibrationGivesVehicleFrameCloud) {
  const std::string calib = test::SourcePath("config/calibration/romo_sample.yaml");
  test::ScratchDir out;
  // A wall 6 m ahead of the front rig, rendered as an ideal pair; rectification of the sample
  // (small distortion) changes it slightly, which the matcher tolerates.
  RectifiedGeometry g;
  g.focal_px = 400.0;
  g.baseline_m = 0.25;
  g.cx_px = 390.5;
  g.cy_px = 290.5;
  const SyntheticPair pair = RenderPlanePair(g, 782, 582, Eigen::Vector3d(0, 0, 1), 6.0, 9);
  cv::imwrite(out / "l.png", pair.left);
  cv::imwrite(out / "r.png", pair.right);
  const test::CommandResult r = test::RunRomo("stereo --left " + (out / "l.png") + " --right " + (out / "r.png") +
                                              " --calib " + calib + " --rig 0 --out " + (out / "o"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const PointCloud cloud = LoadPcd(out / "o/cloud.pcd");
  ASSERT_GT(cloud.size(), 100000u);
  // Front rig at x = 1.4 m looking forward: the wall lies ahead of the vehicle.
  EXPECT_GT(cloud.xyz.row(0).mean(), 1.4f + 3.0f);
}

TEST(StereoCliTest, BadInputExitsTwoWithReason) {
  ROMO_REQUIRE_SHARED_DATA("middlebury/venus/im2.png");
  const std::string dir = test::SharedData("middlebury/venus/");
  test::ScratchDir out;
  test::CommandResult r = test::RunRomo("stereo --left " + dir + "im2.png --right " + dir + "im6.png --ndisp 100 --out " +
                                        out.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(Contains(r.err, "disparity_size = 100")) << r.err;
  r = test::RunRomo("stereo --left /nonexistent/a.png --right " + dir + "im6.png --out " + out.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(Contains(r.err, "/nonexistent/a.png")) << r.err;
  // Venus is 434x383, the sample calibration 782x582.
  r = test::RunRomo("stereo --left " + dir + "im2.png --right " + dir + "im6.png --calib " +
                    test::SourcePath("config/calibration/romo_sample.yaml") + " --out " + out.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(Contains(r.err, "434x383")) << r.err;
  r = test::RunRomo("eval stereo --left " + dir + "im2.png --right " + dir + "im6.png --gt /nonexistent/gt.png "
                    "--gt-scale 8 --ndisp 32");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(Contains(r.err, "/nonexistent/gt.png")) << r.err;
}

}  // namespace
}  // namespace romo::stereo
