#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/mapping/octree.hpp"

namespace romo::mapping {
namespace {

Eigen::Matrix3Xf GridCloud(int nx, int ny, int nz, float step, int per_cell) {
  Eigen::Matrix3Xf xyz(3, nx * ny * nz * per_cell);
  int k = 0;
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < ny; ++y)
      for (int z = 0; z < nz; ++z)
        for (int p = 0; p < per_cell; ++p)
          xyz.col(k++) = Eigen::Vector3f((x + 0.25f + 0.1f * p) * step, (y + 0.5f) * step, (z + 0.5f) * step);
  return xyz;
}

TEST(OctreeTest, CountsLeavesAndNodesOfAKnownGrid) {
  // 8x8x8 occupied cells of 0.1 m, two points each: 512 leaves, full tree of depth 3.
  const Eigen::Matrix3Xf xyz = GridCloud(8, 8, 8, 0.1f, 2);
  VoxelOctree tree(0.1f);
  tree.Build(xyz);
  EXPECT_EQ(tree.leaf_count(), 512u);
  EXPECT_EQ(tree.depth(), 3);
  EXPECT_EQ(tree.node_count(), 1u + 8u + 64u + 512u);
  EXPECT_NEAR(tree.root_size_m(), 0.8f, 1e-6f);
  EXPECT_EQ(tree.point_count(), 1024u);
  for (std::size_t leaf = 0; leaf < tree.leaf_count(); ++leaf) EXPECT_EQ(tree.LeafPointCount(leaf), 2u);
  EXPECT_GT(tree.MemoryBytes(), tree.node_count() * sizeof(VoxelOctree::Node));
}

TEST(OctreeTest, RootGrowsToCoverTheExtent) {
  Eigen::Matrix3Xf xyz(3, 2);
  xyz.col(0) = Eigen::Vector3f(0.f, 0.f, 0.f);
  xyz.col(1) = Eigen::Vector3f(10.05f, 0.f, 0.f);  // 101 leaves of 0.1 m -> 128 = 2^7
  VoxelOctree tree(0.1f);
  tree.Build(xyz);
  EXPECT_EQ(tree.depth(), 7);
  EXPECT_EQ(tree.leaf_count(), 2u);
  EXPECT_EQ(tree.node_count(), 1u + 2u * 7u);  // root plus two separate branches
}

TEST(OctreeTest, FindLeafReturnsThePointsOfThatVoxel) {
  const Eigen::Matrix3Xf xyz = GridCloud(5, 3, 2, 0.2f, 3);
  VoxelOctree tree(0.2f);
  tree.Build(xyz);
  for (std::size_t leaf = 0; leaf < tree.leaf_count(); ++leaf) {
    const Eigen::Vector3i key = tree.LeafKey(leaf);
    ASSERT_EQ(tree.FindLeaf(key), static_cast<std::int64_t>(leaf));
    for (const int* p = tree.LeafPointsBegin(leaf); p != tree.LeafPointsEnd(leaf); ++p) {
      const Eigen::Vector3f local = (xyz.col(*p) - tree.origin()) / 0.2f;
      EXPECT_EQ(static_cast<int>(std::floor(local.x())), key.x());
      EXPECT_EQ(static_cast<int>(std::floor(local.y())), key.y());
      EXPECT_EQ(static_cast<int>(std::floor(local.z())), key.z());
    }
  }
  EXPECT_EQ(tree.FindLeaf(Eigen::Vector3i(5, 0, 0)), -1);   // empty voxel inside the root
  EXPECT_EQ(tree.FindLeaf(Eigen::Vector3i(-1, 0, 0)), -1);  // outside
}

TEST(OctreeTest, DepthFirstTraversalVisitsEveryNodeOnceParentsFirst) {
  const Eigen::Matrix3Xf xyz = GridCloud(7, 5, 3, 0.1f, 1);
  VoxelOctree tree(0.1f);
  tree.Build(xyz);
  std::vector<int> seen(tree.node_count(), 0);
  std::size_t leaves = 0;
  int last_level = -1;
  bool depth_first = true;
  tree.TraverseDepthFirst([&](const VoxelOctree::Node& n, std::size_t i) {
    ++seen[i];
    if (n.level == tree.depth()) ++leaves;
    // Depth-first: the level never jumps down by more than one step.
    if (n.level > last_level + 1) depth_first = false;
    last_level = n.level;
  });
  for (int s : seen) EXPECT_EQ(s, 1);
  EXPECT_EQ(leaves, tree.leaf_count());
  EXPECT_TRUE(depth_first);
}

TEST(OctreeTest, BadInputGivesErrorsOrEmptyTrees) {
  EXPECT_THROW(VoxelOctree(0.f), romo::Error);
  EXPECT_THROW(VoxelOctree(-0.1f), romo::Error);
  // Braces: VoxelOctree(std::numeric_limits<float>::quiet_NaN()) alone is a declaration to clang.
  EXPECT_THROW(VoxelOctree{std::numeric_limits<float>::quiet_NaN()}, romo::Error);
  VoxelOctree tree(0.1f);
  tree.Build(Eigen::Matrix3Xf(3, 0));
  EXPECT_EQ(tree.leaf_count(), 0u);
  EXPECT_EQ(tree.node_count(), 0u);
  Eigen::Matrix3Xf bad(3, 3);
  bad.col(0).setConstant(std::numeric_limits<float>::quiet_NaN());
  bad.col(1).setConstant(std::numeric_limits<float>::infinity());
  bad.col(2) = Eigen::Vector3f(1.f, std::numeric_limits<float>::quiet_NaN(), 0.f);
  tree.Build(bad);
  EXPECT_EQ(tree.leaf_count(), 0u);
  EXPECT_EQ(tree.skipped_non_finite(), 3u);
  Eigen::Matrix3Xf one(3, 1);
  one.col(0) = Eigen::Vector3f(3.f, -2.f, 1.f);
  tree.Build(one);
  EXPECT_EQ(tree.leaf_count(), 1u);
  EXPECT_EQ(tree.depth(), 0);
  // Extent too large for 21 levels at this leaf size: a clear error, not a wrap-around.
  Eigen::Matrix3Xf huge(3, 2);
  huge.col(0) = Eigen::Vector3f::Zero();
  huge.col(1) = Eigen::Vector3f(1e6f, 0.f, 0.f);
  VoxelOctree fine(0.001f);
  EXPECT_THROW(fine.Build(huge), romo::Error);
  std::vector<int> out_of_range{5};
  EXPECT_THROW(tree.Build(one, &out_of_range), romo::Error);
}

}  // namespace
}  // namespace romo::mapping
