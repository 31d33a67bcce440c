#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/mapping/ground_removal.hpp"
#include "romo/mapping/synthetic_scene.hpp"

namespace romo::mapping {
namespace {

TEST(GroundRemovalTest, RefinesATiltedOffsetGroundAndKeepsObjects) {
  SyntheticSceneParams sp;
  sp.density_per_m2 = 400.f;
  sp.ground_half_extent_m = 10.f;
  sp.noise_m = 0.01f;
  SceneObject car;
  car.center_xy = {5.f, 2.f};
  car.size = {4.5f, 1.8f, 1.5f};
  SceneObject ped;
  ped.shape = SceneObject::Shape::kCylinder;
  ped.center_xy = {-3.f, -2.f};
  ped.size = {0.5f, 0.5f, 1.75f};
  SyntheticScene scene = MakeSyntheticScene({car, ped}, sp);
  // The vehicle sits 0.08 m high and pitched 2 deg: the true ground is off the prior.
  constexpr float kPitchRad = 0.0349f, kOffsetM = -0.08f;
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::AngleAxisf(kPitchRad, Eigen::Vector3f::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3f(0.f, 0.f, kOffsetM);
  scene.cloud.Transform(T);

  GroundRemovalParams params;
  const GroundRemoval g = RemoveGround(scene.cloud, params);
  ASSERT_TRUE(g.refined);
  const Eigen::Vector3f true_normal = T.linear() * Eigen::Vector3f::UnitZ();
  constexpr float kNormalAngleToleranceRad = 0.005f;  // 1 cm noise over 20 m of ground
  EXPECT_LT(std::acos(std::min(1.f, g.plane.normal.dot(true_normal))), kNormalAngleToleranceRad);
  constexpr float kOffsetToleranceM = 0.01f;  // the noise sigma
  EXPECT_NEAR(g.plane.SignedDistance(Eigen::Vector3f::Zero()), -kOffsetM, kOffsetToleranceM);

  std::size_t ground_points = 0, removed_ground = 0, object_points = 0, kept_object_high = 0,
              object_high = 0;
  for (std::size_t i = 0; i < scene.labels.size(); ++i) (scene.labels[i] < 0 ? ground_points : object_points)++;
  for (int i : g.ground) removed_ground += scene.labels[i] < 0 ? 1 : 0;
  for (std::size_t i = 0; i < scene.labels.size(); ++i) {
    // Object points higher than the tolerance band must all survive.
    if (scene.labels[i] >= 0 && g.plane.SignedDistance(scene.cloud.xyz.col(i)) > params.height_tolerance_m + 0.05f) ++object_high;
  }
  for (int i : g.obstacles) {
    if (scene.labels[i] >= 0 && g.plane.SignedDistance(scene.cloud.xyz.col(i)) > params.height_tolerance_m + 0.05f) ++kept_object_high;
  }
  EXPECT_EQ(removed_ground, ground_points);  // every ground point removed
  EXPECT_EQ(kept_object_high, object_high);
  EXPECT_GT(object_high, object_points * 9 / 10);
  // RANSAC sees only the prior's search band; within it, 0.01 m noise vs a 0.05 m threshold
  // leaves practically every ground point an inlier.
  std::size_t ground_in_band = 0;
  for (std::size_t i = 0; i < scene.labels.size(); ++i)
    if (scene.labels[i] < 0 && std::abs(scene.cloud.xyz(2, i) - params.prior_height_m) <= params.search_band_m) ++ground_in_band;
  EXPECT_GT(g.ransac_inliers, static_cast<int>(ground_in_band * 95 / 100));
}

TEST(GroundRemovalTest, WithoutGroundPointsThePriorIsUsedAndReported) {
  SyntheticSceneParams sp;
  sp.density_per_m2 = 400.f;
  SceneObject box;
  box.center_xy = {3.f, 0.f};
  box.size = {1.f, 1.f, 2.f};
  const SyntheticScene scene = MakeSyntheticScene({box}, sp);
  GroundRemovalParams params;
  params.prior_height_m = -0.5f;  // box is above the band: nothing to fit
  params.search_band_m = 0.2f;
  const GroundRemoval g = RemoveGround(scene.cloud, params);
  EXPECT_FALSE(g.refined);
  EXPECT_FLOAT_EQ(g.plane.d, 0.5f);
  EXPECT_EQ(g.obstacles.size(), scene.cloud.size());
  EXPECT_TRUE(g.ground.empty());
  EXPECT_TRUE(RemoveGround(PointCloud{}, params).obstacles.empty());
  params.height_tolerance_m = -1.f;
  EXPECT_THROW(RemoveGround(scene.cloud, params), romo::Error);
}

// Stereo mismatches land far under the ground (0.2-3 m under it in the simulated parking scene):
// removed, but not counted as ground, whose presence says a place is free. Noise under it within
// the tolerance, or within each point's depth sigma when that is larger, stays ground.
TEST(GroundRemovalTest, PointsFarBelowThePlaneAreNotGround) {
  PointCloud cloud;
  for (int x = 0; x < 20; ++x) {
    for (int y = 0; y < 20; ++y) cloud.PushBack(Eigen::Vector3f(0.25f * x, 0.25f * y, 0.f), 0.02f);
  }
  const int first_extra = static_cast<int>(cloud.size());
  cloud.PushBack(Eigen::Vector3f(1.f, 1.f, -0.08f), 0.02f);  // within the 0.1 m tolerance
  cloud.PushBack(Eigen::Vector3f(1.f, 2.f, -0.3f), 0.5f);    // far and uncertain: within 1 sigma
  cloud.PushBack(Eigen::Vector3f(2.f, 1.f, -0.3f), 0.12f);   // 0.3 m under with a 0.12 m sigma
  cloud.PushBack(Eigen::Vector3f(2.f, 2.f, -2.9f), 0.18f);
  cloud.PushBack(Eigen::Vector3f(3.f, 3.f, 1.0f), 0.02f);    // an obstacle

  GroundRemovalParams params;
  const GroundRemoval g = RemoveGround(cloud, params);
  ASSERT_TRUE(g.refined);
  EXPECT_EQ(g.below, (std::vector<int>{first_extra + 2, first_extra + 3}));
  EXPECT_EQ(g.obstacles, (std::vector<int>{first_extra + 4}));
  EXPECT_EQ(g.ground.size(), static_cast<std::size_t>(first_extra + 2));
  EXPECT_EQ(g.ground.back(), first_extra + 1);

  params.below_tolerance_m = std::numeric_limits<float>::infinity();  // everything under is ground
  const GroundRemoval all = RemoveGround(cloud, params);
  EXPECT_TRUE(all.below.empty());
  EXPECT_EQ(all.ground.size(), static_cast<std::size_t>(first_extra + 4));

  params.below_sigmas = -1.f;
  EXPECT_THROW(RemoveGround(cloud, params), romo::Error);
}

}  // namespace
}  // namespace romo::mapping
