#include "romo/stereo/rgbd.hpp"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"

namespace romo::stereo {
namespace {

KinectModel Model() {
  KinectModel k;
  k.ir = {580.0, 580.0, 320.0, 240.0};
  k.rgb = {525.0, 525.0, 318.0, 242.0};
  return k;
}

// Eq. 2.4-2.5: the RGB pixel (i, j) shows the depth pixel ((i - c_rgb) f_ir / f_rgb + c_ir, ...).
TEST(RgbdTest, DepthToRgbFollowsEquations24And25) {
  const KinectModel k = Model();
  // Each depth pixel holds its own index (float: exact up to 2^24), so the warp shows its source.
  cv::Mat depth(480, 640, CV_32FC1);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) depth.at<float>(y, x) = static_cast<float>(y * 640 + x);
  const cv::Mat warped = WarpDepthToRgb(depth, k, cv::Size(640, 480));
  ASSERT_EQ(warped.type(), CV_32FC1);
  for (int j = 10; j < 470; j += 37) {
    for (int i = 10; i < 630; i += 41) {
      const double u = (i - k.rgb.cx) * k.ir.fx / k.rgb.fx + k.ir.cx;
      const double v = (j - k.rgb.cy) * k.ir.fy / k.rgb.fy + k.ir.cy;
      const int value = static_cast<int>(warped.at<float>(j, i));
      if (u < 0.0 || v < 0.0 || u > 639.0 || v > 479.0) {
        EXPECT_EQ(value, 0) << "source outside the depth image: no depth";
        continue;
      }
      // Nearest neighbour: the source pixel is within half a pixel of the analytic position.
      EXPECT_LE(std::abs(value % 640 - u), 0.5 + 1e-6) << i << "," << j;
      EXPECT_LE(std::abs(value / 640 - v), 0.5 + 1e-6) << i << "," << j;
    }
  }
  // RGB pixels whose depth source lies outside the depth image (u < 0 here) get no depth.
  EXPECT_EQ(warped.at<float>(240, 0), 0.f);
}

// Eq. 2.6: a linear ramp survives the bilinear RGB -> depth warp exactly at the mapped position.
TEST(RgbdTest, RgbToDepthFollowsEquation26) {
  const KinectModel k = Model();
  cv::Mat ramp(480, 640, CV_32FC1);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) ramp.at<float>(y, x) = static_cast<float>(x);
  const cv::Mat warped = WarpRgbToDepth(ramp, k, cv::Size(640, 480));
  constexpr double kTolPx = 0.05;  // cv::remap quantises source positions to 1/32 px
  for (int i = 5; i < 635; i += 23) {
    const double expected = (i - k.ir.cx) * k.rgb.fx / k.ir.fx + k.rgb.cx;
    EXPECT_NEAR(warped.at<float>(240, i), expected, kTolPx) << i;
  }
}

TEST(RgbdTest, DepthToCloudGeometryAndSigma) {
  const KinectModel k = Model();
  drivers::RgbdFrame frame;
  frame.depth = drivers::Image::Allocate(drivers::PixelFormat::kMono16, 64, 48);
  frame.depth_scale_m = 0.001;
  std::uint16_t two_m = 2000;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) std::memcpy(frame.depth.row(y) + 2 * x, &two_m, 2);
  std::uint16_t none = 0;
  std::memcpy(frame.depth.row(0), &none, 2);  // one pixel without depth
  const PointCloud cloud = DepthToCloud(frame, k);
  ASSERT_EQ(cloud.size(), 64u * 48u - 1u);
  // Pixel (1, 0) is the first point: x = (1 - 320) * 2 / 580, y = (0 - 240) * 2 / 580.
  EXPECT_NEAR(cloud.xyz(0, 0), (1 - 320.0) * 2.0 / 580.0, 1e-5);
  EXPECT_NEAR(cloud.xyz(1, 0), (0 - 240.0) * 2.0 / 580.0, 1e-5);
  EXPECT_NEAR(cloud.xyz(2, 0), 2.0, 1e-6);
  // Eq. 2.3 with the projector baseline: Z^2 / (b f) * sigma_d.
  EXPECT_NEAR(cloud.sigma_z_m[0], 4.0 / (0.075 * 580.0) * 0.125, 1e-6);
  EXPECT_TRUE(DepthToCloud(frame, k, 1.0).empty());  // everything is 2 m away
}

TEST(RgbdTest, RejectsBadInput) {
  KinectModel k = Model();
  k.ir.fx = 0.0;
  EXPECT_THROW(WarpDepthToRgb(cv::Mat(4, 4, CV_16UC1), k, cv::Size(4, 4)), Error);
  EXPECT_THROW(WarpDepthToRgb(cv::Mat(4, 4, CV_8UC1), Model(), cv::Size(4, 4)), Error);
  drivers::RgbdFrame frame;
  frame.depth = drivers::Image::Allocate(drivers::PixelFormat::kMono8, 4, 4);
  EXPECT_THROW(DepthToCloud(frame, Model()), Error);
  frame.depth = drivers::Image::Allocate(drivers::PixelFormat::kMono16, 4, 4);
  frame.depth_scale_m = 0.0;
  EXPECT_THROW(DepthToCloud(frame, Model()), Error);
}

}  // namespace
}  // namespace romo::stereo
