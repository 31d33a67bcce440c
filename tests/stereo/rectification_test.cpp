#include "romo/stereo/rectification.hpp"

#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "romo/core/check.hpp"
#include "stereo_test_rigs.hpp"

namespace romo::stereo {
namespace {

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(RectificationTest, IdealRigKeepsFocalBaselineAndOrientation) {
  const Rectifier rect(testing::MakeRig(0, 161, 97, /*distortion=*/false));
  const RectifiedGeometry& g = rect.geometry();
  // No distortion, no rotation: rectification is the identity up to OpenCV's floating point.
  constexpr double kTolPx = 1e-6;
  EXPECT_NEAR(g.focal_px, 400.0, kTolPx);
  EXPECT_NEAR(g.baseline_m, 0.25, 1e-9);
  EXPECT_NEAR(g.cx_px, 80.0, kTolPx);
  EXPECT_TRUE(g.R_rig_rect.isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_EQ(rect.Q().rows, 4);
}

// Each map entry must send a rectified pixel to the raw pixel that OpenCV's undistortPoints
// (the reference) sends back to it, on an odd image size.
TEST(RectificationTest, MapsInvertUndistortPointsOnOddSize) {
  const drivers::RigCalibration rig = testing::MakeRig(0, 161, 97);
  const Rectifier rect(rig);
  const RectifiedGeometry& g = rect.geometry();
  // Rectify a coordinate image: remapped x/y tell where each rectified pixel samples the raw one.
  cv::Mat xs(97, 161, CV_32FC1), ys(97, 161, CV_32FC1);
  for (int y = 0; y < 97; ++y)
    for (int x = 0; x < 161; ++x) {
      xs.at<float>(y, x) = static_cast<float>(x);
      ys.at<float>(y, x) = static_cast<float>(y);
    }
  cv::Mat rx, ry;
  rect.Rectify(xs, ys, &rx, &ry);  // the right map would differ only by R2/P2; use left twice
  cv::Mat K = (cv::Mat_<double>(3, 3) << 400, 0, 80, 0, 400, 48, 0, 0, 1);
  cv::Mat D = (cv::Mat_<double>(1, 5) << -0.02, 0.004, 0, 0, 0);
  cv::Mat R1(3, 3, CV_64F), P1 = (cv::Mat_<double>(3, 3) << g.focal_px, 0, g.cx_px, 0, g.focal_px, g.cy_px, 0, 0, 1);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R1.at<double>(r, c) = g.R_rig_rect(c, r);
  // Fixed-point maps (CV_16SC2, 1/32 px) plus bilinear sampling: 0.05 px is ample.
  constexpr double kTolPx = 0.05;
  for (int y = 5; y < 92; y += 7) {
    for (int x = 5; x < 156; x += 9) {
      std::vector<cv::Point2f> raw{{rx.at<float>(y, x), ry.at<float>(y, x)}}, back;
      cv::undistortPoints(raw, back, K, D, R1, P1);
      EXPECT_NEAR(back[0].x, x, kTolPx);
      EXPECT_NEAR(back[0].y, y, kTolPx);
    }
  }
}

TEST(RectificationTest, RejectsNonRectifiableCalibrations) {
  auto rig = [] { return testing::MakeRig(3, 160, 120); };
  drivers::RigCalibration r = rig();
  r.T = Eigen::Vector3d(0.0, -0.25, 0.0);
  EXPECT_NE(ErrorOf([&] { Rectifier x(r); }).find("horizontal"), std::string::npos);
  r = rig();
  r.T = Eigen::Vector3d(0.25, 0.0, 0.0);
  EXPECT_NE(ErrorOf([&] { Rectifier x(r); }).find("swapped"), std::string::npos);
  r = rig();
  r.T = Eigen::Vector3d::Zero();
  EXPECT_NE(ErrorOf([&] { Rectifier x(r); }).find("baseline"), std::string::npos);
  r = rig();
  r.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_NE(ErrorOf([&] { Rectifier x(r); }).find("deg apart"), std::string::npos);
  r = rig();
  r.R(0, 0) = 2.0;
  EXPECT_NE(ErrorOf([&] { Rectifier x(r); }).find("not a rotation"), std::string::npos);
  r = rig();
  r.left.K(0, 0) = 0.0;
  EXPECT_NE(ErrorOf([&] { Rectifier x(r); }).find("fx = 0"), std::string::npos);
  r = rig();
  r.width_px = 0;
  EXPECT_NE(ErrorOf([&] { Rectifier x(r); }).find("rig 3"), std::string::npos);
}

TEST(RectificationTest, RejectsImagesOfAnotherSize) {
  const Rectifier rect(testing::MakeRig(0, 160, 120));
  const cv::Mat ok(120, 160, CV_8UC1, cv::Scalar(1)), wrong(121, 160, CV_8UC1, cv::Scalar(1));
  cv::Mat a, b;
  EXPECT_NE(ErrorOf([&] { rect.Rectify(ok, wrong, &a, &b); }).find("160x121"), std::string::npos);
  EXPECT_NO_THROW(rect.Rectify(ok, ok, &a, &b));
}

}  // namespace
}  // namespace romo::stereo
