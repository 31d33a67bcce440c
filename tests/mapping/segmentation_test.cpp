#include <cmath>
#include <limits>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/mapping/segmentation.hpp"
#include "romo/mapping/synthetic_scene.hpp"

namespace romo::mapping {
namespace {

using Shape = SceneObject::Shape;

SceneObject Box(float x, float y, float l, float w, float h, float yaw = 0.f) {
  SceneObject o;
  o.shape = Shape::kBox;
  o.center_xy = {x, y};
  o.size = {l, w, h};
  o.yaw_rad = yaw;
  return o;
}
SceneObject Cylinder(float x, float y, float d, float h) {
  SceneObject o;
  o.shape = Shape::kCylinder;
  o.center_xy = {x, y};
  o.size = {d, d, h};
  return o;
}

/// Ground-truth groups (object label -> point indices) restricted to non-ground points.
std::set<std::vector<int>> TruthGroups(const SyntheticScene& scene, const std::vector<std::vector<int>>& merge = {}) {
  std::vector<int> group_of(scene.objects.size());
  for (std::size_t i = 0; i < group_of.size(); ++i) group_of[i] = static_cast<int>(i);
  for (const auto& m : merge)
    for (int o : m) group_of[o] = m.front();
  std::vector<std::vector<int>> groups(scene.objects.size());
  for (std::size_t i = 0; i < scene.labels.size(); ++i)
    if (scene.labels[i] >= 0) groups[group_of[scene.labels[i]]].push_back(static_cast<int>(i));
  std::set<std::vector<int>> out;
  for (auto& g : groups)
    if (!g.empty()) out.insert(g);
  return out;
}

std::vector<int> ObjectPoints(const SyntheticScene& scene) {
  std::vector<int> idx;
  for (std::size_t i = 0; i < scene.labels.size(); ++i)
    if (scene.labels[i] >= 0) idx.push_back(static_cast<int>(i));
  return idx;
}

TEST(SegmentationTest, SeparatedBoxesAndCylindersAreExactBlobs) {
  SyntheticSceneParams sp;
  sp.density_per_m2 = 2000.f;
  sp.noise_m = 0.005f;
  const auto scene = MakeSyntheticScene(
      {Box(0, 0, 4.5f, 1.8f, 1.5f, 0.3f), Box(6, 1, 1.f, 1.f, 1.f), Cylinder(-3, 3, 0.5f, 1.75f),
       Cylinder(-3, 4, 0.5f, 1.75f), Box(3, -4, 2.f, 0.5f, 0.8f, -1.f)},
      sp);
  SegmentationParams params;
  params.leaf_size_m = 0.1f;
  const Segmentation seg = SegmentBlobs(scene.cloud.xyz, params);
  EXPECT_EQ(seg.blobs.size(), 5u);
  const std::set<std::vector<int>> got(seg.blobs.begin(), seg.blobs.end());
  EXPECT_EQ(got, TruthGroups(scene));  // membership exact: every point in its object's blob
}

TEST(SegmentationTest, TouchingPairIsOneBlobSeparatedPairIsTwo) {
  SyntheticSceneParams sp;
  sp.density_per_m2 = 2000.f;
  // Boxes sharing a face (gap 0) form one connected surface; 0.5 m apart they do not.
  const auto touching = MakeSyntheticScene({Box(0, 0, 1, 1, 1), Box(1, 0, 1, 1, 1.5f)}, sp);
  const auto separated = MakeSyntheticScene({Box(0, 0, 1, 1, 1), Box(1.5f, 0, 1, 1, 1.5f)}, sp);
  SegmentationParams params;
  params.leaf_size_m = 0.1f;
  const auto a = SegmentBlobs(touching.cloud.xyz, params);
  ASSERT_EQ(a.blobs.size(), 1u);
  EXPECT_EQ(std::set<std::vector<int>>(a.blobs.begin(), a.blobs.end()), TruthGroups(touching, {{0, 1}}));
  const auto b = SegmentBlobs(separated.cloud.xyz, params);
  ASSERT_EQ(b.blobs.size(), 2u);
  EXPECT_EQ(std::set<std::vector<int>>(b.blobs.begin(), b.blobs.end()), TruthGroups(separated));
}

TEST(SegmentationTest, ImplausiblyLargeBlobIsSplitAtAFinerLeaf) {
  // Two pedestrians 0.25 m apart merge at a 0.3 m leaf (Fig. 3.8); re-clustering blobs larger
  // than one person (diagonal > 2 m; one person: 1.89 m) at a third of the leaf (0.1 m, which
  // separates gaps >= 0.2 m) splits them again.
  SyntheticSceneParams sp;
  sp.density_per_m2 = 3000.f;
  const auto scene = MakeSyntheticScene({Cylinder(0, 0, 0.5f, 1.75f), Cylinder(0.75f, 0, 0.5f, 1.75f)}, sp);
  SegmentationParams params;
  params.leaf_size_m = 0.3f;
  EXPECT_EQ(SegmentBlobs(scene.cloud.xyz, params).blobs.size(), 1u);
  params.max_object_extent_m = 2.0f;
  params.refine_factor = 0.333f;
  params.max_refine_levels = 1;
  const auto seg = SegmentBlobs(scene.cloud.xyz, params);
  ASSERT_EQ(seg.blobs.size(), 2u);
  EXPECT_EQ(seg.refined, 1u);
  EXPECT_EQ(std::set<std::vector<int>>(seg.blobs.begin(), seg.blobs.end()), TruthGroups(scene));
}

TEST(SegmentationTest, SubsetAndSizeLimitsAreHonoured) {
  SyntheticSceneParams sp;
  sp.density_per_m2 = 1000.f;
  sp.ground_half_extent_m = 5.f;
  const auto scene = MakeSyntheticScene({Box(0, 0, 1, 1, 1), Box(3, 0, 0.3f, 0.3f, 0.3f)}, sp);
  const std::vector<int> objects = ObjectPoints(scene);
  SegmentationParams params;
  params.leaf_size_m = 0.1f;
  // Only the subset is clustered: the ground would otherwise join everything.
  const auto all = SegmentBlobs(scene.cloud.xyz, params, &objects);
  ASSERT_EQ(all.blobs.size(), 2u);
  const std::size_t small = all.blobs[1].size();
  params.min_blob_points = static_cast<int>(small) + 1;
  const auto big_only = SegmentBlobs(scene.cloud.xyz, params, &objects);
  EXPECT_EQ(big_only.blobs.size(), 1u);
  EXPECT_EQ(big_only.dropped_small, 1u);
  params.min_blob_points = 1;
  params.max_blob_points = static_cast<int>(small);
  const auto small_only = SegmentBlobs(scene.cloud.xyz, params, &objects);
  ASSERT_EQ(small_only.blobs.size(), 1u);
  EXPECT_EQ(small_only.blobs[0].size(), small);
  EXPECT_EQ(small_only.dropped_large, 1u);
}

TEST(SegmentationTest, BadInputGivesErrorsOrEmptyResults) {
  SegmentationParams params;
  EXPECT_TRUE(SegmentBlobs(Eigen::Matrix3Xf(3, 0), params).blobs.empty());
  Eigen::Matrix3Xf nan(3, 100);
  nan.setConstant(std::numeric_limits<float>::quiet_NaN());
  nan.col(7).setConstant(std::numeric_limits<float>::infinity());
  const auto s = SegmentBlobs(nan, params);
  EXPECT_TRUE(s.blobs.empty());
  EXPECT_EQ(s.skipped_non_finite, 100u);
  Eigen::Matrix3Xf one(3, 1);
  one.col(0) = Eigen::Vector3f(1, 2, 3);
  params.min_blob_points = 1;
  const auto single = SegmentBlobs(one, params);
  ASSERT_EQ(single.blobs.size(), 1u);
  EXPECT_EQ(single.blobs[0], std::vector<int>{0});
  params.leaf_size_m = 0.f;
  EXPECT_THROW(SegmentBlobs(one, params), romo::Error);
  params.leaf_size_m = -1.f;
  EXPECT_THROW(SegmentBlobs(one, params), romo::Error);
  params.leaf_size_m = 0.1f;
  params.min_blob_points = 0;
  EXPECT_THROW(SegmentBlobs(one, params), romo::Error);
  params.min_blob_points = 1;
  const std::vector<int> bad_subset{3};
  EXPECT_THROW(SegmentBlobs(one, params, &bad_subset), romo::Error);
}

/// Random clusters, chains and stray points of an awkward count, some exactly on voxel faces, a few
/// non-finite; centred at @p offset (negative coordinates exercise the snapped origin).
Eigen::Matrix3Xf RandomCloud(std::uint64_t seed, int n, float leaf_m, const Eigen::Vector3f& offset) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> uni(-1.f, 1.f);
  std::normal_distribution<float> gauss(0.f, 1.f);
  std::uniform_int_distribution<int> kind(0, 9);
  Eigen::Matrix3Xf xyz(3, n);
  Eigen::Vector3f centre = offset;
  for (int i = 0; i < n; ++i) {
    if (i % 97 == 0) centre = offset + Eigen::Vector3f(3.f * uni(rng), 2.f * uni(rng), 1.f * uni(rng));
    const int k = kind(rng);
    Eigen::Vector3f p;
    if (k < 6) {
      p = centre + 0.15f * Eigen::Vector3f(gauss(rng), gauss(rng), gauss(rng));
    } else if (k < 8) {
      p = centre + Eigen::Vector3f(uni(rng), 0.f, 0.f) * 0.8f;  // chain along x
    } else if (k < 9) {
      p = offset + Eigen::Vector3f(3.f * uni(rng), 2.f * uni(rng), 1.f * uni(rng));  // stray
    } else {
      // On a voxel face: where floor() decides which leaf a point belongs to.
      p = (centre / leaf_m).array().round().matrix() * leaf_m;
    }
    xyz.col(i) = p;
  }
  for (int i = 5; i < n; i += 211) xyz(i % 3, i) = i % 2 ? std::numeric_limits<float>::quiet_NaN() : -INFINITY;
  return xyz;
}

void ExpectSameSegmentation(const Segmentation& a, const Segmentation& b) {
  EXPECT_EQ(a.blobs, b.blobs);
  EXPECT_EQ(a.occupied_leaves, b.occupied_leaves);
  EXPECT_EQ(a.dropped_small, b.dropped_small);
  EXPECT_EQ(a.dropped_large, b.dropped_large);
  EXPECT_EQ(a.refined, b.refined);
  EXPECT_EQ(a.skipped_non_finite, b.skipped_non_finite);
}

TEST(SegmentationTest, DenseGridMatchesOctreeReferenceOnRandomClouds) {
  // A few-metre extent at these leaves is a grid far under 1 MiB: the default always takes the
  // dense path; dense_grid_max_bytes = 0 forces the octree-hash reference.
  std::size_t compared_blobs = 0, refined = 0, dropped_small = 0, dropped_large = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const float leaf_m = 0.05f + 0.037f * static_cast<float>(seed);
    const int n = 1001 + 1777 * static_cast<int>(seed);
    const Eigen::Vector3f offset(seed % 2 ? -7.3f : 2.1f, seed % 3 ? 0.45f : -12.f, -0.9f);
    const Eigen::Matrix3Xf xyz = RandomCloud(seed, n, leaf_m, offset);
    SegmentationParams fast;
    fast.leaf_size_m = leaf_m;
    fast.min_blob_points = 1 + static_cast<int>(seed % 4) * 3;
    fast.max_blob_points = seed % 2 ? std::numeric_limits<int>::max() : n / 3;
    if (seed >= 4) {
      fast.max_object_extent_m = 1.5f;  // refinement runs on blob subsets
      fast.max_refine_levels = static_cast<int>(seed) - 3;
    }
    SegmentationParams reference = fast;
    reference.dense_grid_max_bytes = 0;
    const Segmentation a = SegmentBlobs(xyz, fast);
    SCOPED_TRACE("seed " + std::to_string(seed));
    ExpectSameSegmentation(a, SegmentBlobs(xyz, reference));
    // And on a subset given out of order.
    std::vector<int> subset;
    for (int i = n - 1; i >= 0; i -= 2) subset.push_back(i);
    ExpectSameSegmentation(SegmentBlobs(xyz, fast, &subset), SegmentBlobs(xyz, reference, &subset));
    compared_blobs += a.blobs.size();
    refined += a.refined;
    dropped_small += a.dropped_small;
    dropped_large += a.dropped_large;
  }
  // The clouds really do exercise many blobs, refinement and both size limits.
  EXPECT_GT(compared_blobs, 30u);
  EXPECT_GT(refined, 0u);
  EXPECT_GT(dropped_small, 0u);
  EXPECT_GT(dropped_large, 0u);
}

TEST(SegmentationTest, WideSparseExtentFallsBackToTheOctreeWithTheSameResult) {
  // Two small clumps 1.5 km apart at a 2 cm leaf: a dense grid would need ~10^16 cells.
  Eigen::Matrix3Xf xyz(3, 8);
  for (int i = 0; i < 4; ++i) {
    xyz.col(i) = Eigen::Vector3f(0.01f * static_cast<float>(i), 0.f, 0.f);
    xyz.col(4 + i) = Eigen::Vector3f(1500.f, 1500.f + 0.01f * static_cast<float>(i), 1500.f);
  }
  SegmentationParams params;
  params.leaf_size_m = 0.02f;
  params.min_blob_points = 1;
  const Segmentation seg = SegmentBlobs(xyz, params);
  ASSERT_EQ(seg.blobs.size(), 2u);
  EXPECT_EQ(seg.blobs[0], (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(seg.blobs[1], (std::vector<int>{4, 5, 6, 7}));
  // A tight budget sends even a small cloud through the octree, with the same answer.
  const SyntheticScene scene = MakeParkingScene(20000, 3);
  SegmentationParams tight;
  tight.dense_grid_max_bytes = 1024;
  ExpectSameSegmentation(SegmentBlobs(scene.cloud.xyz, tight), SegmentBlobs(scene.cloud.xyz, SegmentationParams{}));
}

}  // namespace
}  // namespace romo::mapping
