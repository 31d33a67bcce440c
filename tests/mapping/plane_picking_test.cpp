// Several planes by repeated RANSAC, and a plane forced through three picked pixels.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/mapping/plane_picking.hpp"

namespace romo::mapping {
namespace {

// An organized 80x60 "depth image" seen from the origin: a table (y = 0.4 m below the camera)
// in the lower half, a wall (z = 2.5 m) in the upper half, a box on the table, some holes.
Eigen::Matrix3Xf RoomCloud(int w, int h) {
  std::mt19937 rng(2);
  std::normal_distribution<float> n(0.f, 0.003f);
  Eigen::Matrix3Xf xyz(3, w * h);
  const float f = 60.f, nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3f ray((u - w / 2.f) / f, (v - h / 2.f) / f, 1.f);
      float t = 2.5f;  // wall
      if (ray.y() > 0 && 0.4f / ray.y() < t) t = 0.4f / ray.y();  // table plane y = 0.4
      if (u > 35 && u < 45 && v > 36 && v < 44) t *= 0.9f;  // a box standing on the table
      Eigen::Vector3f p = ray * (t + n(rng));
      if ((u * 7 + v * 13) % 29 == 0) p.setConstant(nan);  // holes
      xyz.col(v * w + u) = p;
    }
  }
  return xyz;
}

TEST(PlanePickingTest, RepeatedRansacFindsTableAndWall) {
  const Eigen::Matrix3Xf xyz = RoomCloud(80, 60);
  MultiPlaneParams params;
  params.ransac.inlier_threshold_m = 0.015f;
  params.min_inliers = 300;
  const auto planes = FindPlanes(xyz, params);
  ASSERT_GE(planes.size(), 2u);
  // Table: normal along y, 0.4 m away; wall: normal along z, 2.5 m away (either sign).
  constexpr float kMaxNormalErr = 0.02f;  // ~1 deg
  constexpr float kMaxOffsetErrM = 0.02f;
  bool table = false, wall = false;
  for (const auto& p : planes) {
    if (std::abs(std::abs(p.plane.normal.y()) - 1.f) < kMaxNormalErr &&
        std::abs(std::abs(p.plane.d) - 0.4f) < kMaxOffsetErrM) table = true;
    if (std::abs(std::abs(p.plane.normal.z()) - 1.f) < kMaxNormalErr &&
        std::abs(std::abs(p.plane.d) - 2.5f) < kMaxOffsetErrM) wall = true;
  }
  EXPECT_TRUE(table);
  EXPECT_TRUE(wall);
  // Each found plane's inliers are disjoint from the earlier ones'.
  std::vector<int> seen(xyz.cols(), 0);
  for (const auto& p : planes)
    for (int i : p.inliers) EXPECT_EQ(seen[i]++, 0);
}

TEST(PlanePickingTest, ThreePickedPixelsForceThePlaneAndBadPixelsThrow) {
  const int w = 80, h = 60;
  const Eigen::Matrix3Xf xyz = RoomCloud(w, h);
  const auto fit = PlaneFromPickedPixels(xyz, w, {{{10, 50}, {70, 52}, {40, 57}}}, 0.015f);
  constexpr float kMaxNormalErr = 0.05f;  // three single noisy points: a few degrees
  EXPECT_LT(std::abs(std::abs(fit.plane.normal.y()) - 1.f), kMaxNormalErr);
  EXPECT_GT(fit.inliers.size(), 500u);
  EXPECT_THROW(PlaneFromPickedPixels(xyz, w, {{{10, 50}, {70, 52}, {90, 57}}}, 0.015f), romo::Error);
  // (0,0) is a hole: (0*7 + 0*13) % 29 == 0.
  EXPECT_THROW(PlaneFromPickedPixels(xyz, w, {{{0, 0}, {70, 52}, {40, 57}}}, 0.015f), romo::Error);
  // The same pixel twice: no triangle.
  EXPECT_THROW(PlaneFromPickedPixels(xyz, w, {{{10, 50}, {10, 50}, {30, 50}}}, 0.015f), romo::Error);
}

}  // namespace
}  // namespace romo::mapping
