#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/mapping/plane_ransac.hpp"
#include "romo/stereo/pcd_io.hpp"
#include "test_support.hpp"

namespace romo::mapping {
namespace {

TEST(PlaneRansacTest, IterationCountFollowsEquation32) {
  // N = log(1-p)/log(1-(1-eps)^s): p = 0.99, eps = 0.5, s = 3 -> log(0.01)/log(0.875) = 34.5 -> 35.
  EXPECT_EQ(RansacIterations(0.99, 0.5, 3, 100000), 35);
  // eps = 0.8: log(0.01)/log(1-0.008) = 573.4 -> 574.
  EXPECT_EQ(RansacIterations(0.99, 0.8, 3, 100000), 574);
  EXPECT_EQ(RansacIterations(0.99, 0.8, 3, 100), 100);  // capped
  EXPECT_EQ(RansacIterations(0.99, 0.0, 3, 100), 1);    // no outliers: one sample suffices
  EXPECT_THROW(RansacIterations(1.0, 0.5, 3, 10), romo::Error);
  EXPECT_THROW(RansacIterations(0.99, 1.0, 3, 10), romo::Error);
}

TEST(PlaneRansacTest, FindsPclsPlaneInSacPlaneTestPcd) {
  ROMO_REQUIRE_SHARED_DATA("pcl/sac_plane_test.pcd");
  const PointCloud cloud = stereo::LoadPcd(test::SharedData("pcl/sac_plane_test.pcd"));
  PlaneRansacParams params;
  params.inlier_threshold_m = 0.03f;  // PCL's own test setting
  const auto fit = FitPlaneRansac(cloud.xyz, params);
  ASSERT_TRUE(fit.has_value());
  // PCL's test: > 2000 inliers, a/d, b/d, c/d within 0.1 of (-0.8964, -0.5868, -1.208).
  constexpr double kCoefficientTolerance = 0.1;
  EXPECT_GT(fit->inliers.size(), 2000u);
  const Eigen::Vector4f c = fit->plane.Coefficients();
  EXPECT_NEAR(c[0] / c[3], -0.8964, kCoefficientTolerance);
  EXPECT_NEAR(c[1] / c[3], -0.5868, kCoefficientTolerance);
  EXPECT_NEAR(c[2] / c[3], -1.208, kCoefficientTolerance);
  EXPECT_NEAR(fit->plane.normal.norm(), 1.0f, 1e-5f);
}

TEST(PlaneRansacTest, AxisConstraintPicksTheHorizontalPlaneOverALargerWall) {
  // A wall (x = 2, 6000 points) and a floor (z = 0, 3000 points): unconstrained RANSAC finds the
  // wall, the z-axis constraint finds the floor.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(-3.f, 3.f);
  std::normal_distribution<float> noise(0.f, 0.005f);
  Eigen::Matrix3Xf xyz(3, 9000);
  for (int i = 0; i < 6000; ++i) xyz.col(i) = Eigen::Vector3f(2.f + noise(rng), u(rng), 1.5f + 0.5f * u(rng));
  for (int i = 6000; i < 9000; ++i) xyz.col(i) = Eigen::Vector3f(u(rng), u(rng), noise(rng));
  PlaneRansacParams params;
  params.inlier_threshold_m = 0.02f;
  const auto free_fit = FitPlaneRansac(xyz, params);
  ASSERT_TRUE(free_fit);
  EXPECT_GT(std::abs(free_fit->plane.normal.x()), 0.99f);
  params.axis = Eigen::Vector3f::UnitZ();
  params.max_axis_angle_rad = 0.1f;
  const auto floor_fit = FitPlaneRansac(xyz, params);
  ASSERT_TRUE(floor_fit);
  constexpr float kNormalTolerance = 0.01f;  // 5 mm noise over 6 m: well under 0.6 deg
  EXPECT_NEAR(floor_fit->plane.normal.z(), 1.f, kNormalTolerance);  // oriented to the axis
  EXPECT_NEAR(floor_fit->plane.d, 0.f, 0.01f);
  EXPECT_GE(floor_fit->inliers.size(), 2990u);  // 3-sigma band of 0.005 m noise at 0.02 m: ~all
  // Plus the wall's foot below 0.02 m: 6000 * 0.02 / 3 = 40 expected, +-20 at 3 sigma.
  EXPECT_LE(floor_fit->inliers.size(), 3000u + 60u);
}

TEST(PlaneRansacTest, DegenerateInputReturnsNothing) {
  PlaneRansacParams params;
  EXPECT_FALSE(FitPlaneRansac(Eigen::Matrix3Xf(3, 0), params));
  Eigen::Matrix3Xf line(3, 50);
  for (int i = 0; i < 50; ++i) line.col(i) = Eigen::Vector3f(0.1f * i, 0.f, 0.f);
  EXPECT_FALSE(FitPlaneRansac(line, params));
  Eigen::Matrix3Xf nan(3, 10);
  nan.setConstant(std::nanf(""));
  EXPECT_FALSE(FitPlaneRansac(nan, params));
  params.inlier_threshold_m = -1.f;
  EXPECT_THROW(FitPlaneRansac(line, params), romo::Error);
}

}  // namespace
}  // namespace romo::mapping
