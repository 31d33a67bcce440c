#pragma once
// Connected components of occupied voxels, per point: the two ways segmentation labels a cloud.
// Both voxelise exactly as the octree does (SnappedOrigin, VoxelCodes' float expression), so they
// give the same partition; the dense grid is the fast one, the octree the reference and the
// fallback for extents too large for a grid.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "internal/voxel_keys.hpp"

namespace romo::mapping::internal {

/// Component of every finite point; the points are `indices` (into the cloud) in their own order.
struct PointComponents {
  std::vector<int> indices;           ///< cloud indices of the labelled (finite) points
  bool ascending = false;             ///< indices strictly increasing
  std::vector<std::uint32_t> labels;  ///< component per entry of indices, 0 .. sizes.size()-1
  std::vector<std::uint32_t> sizes;   ///< points per component
  std::size_t occupied_voxels = 0;
};

/// Bytes DenseGridComponents needs for the grid over @p finite's bounds at @p voxel_m (bit
/// planes and ranks, the padding included); SIZE_MAX when the grid cannot be indexed in 32 bits.
std::size_t DenseGridBytes(const FinitePoints& finite, float voxel_m);

/// Labels @p finite's points by 26-connected components of their voxels using a padded dense bit
/// grid over the bounding box: occupancy bits, per-word ranks that number the occupied voxels
/// densely, and an iterative DFS that tests three x-neighbours with one load.
/// @pre DenseGridBytes(finite, voxel_m) != SIZE_MAX. Consumes finite.indices.
/// @throws romo::Error (as the octree) when the extent needs more than 2^21 voxels per axis.
PointComponents DenseGridComponents(const Eigen::Matrix3Xf& xyz, FinitePoints finite, float voxel_m);

/// The same labelling by DFS over the leaves of a VoxelOctree (hash lookups per neighbour): the
/// plain reference, and the path for extents whose dense grid would not fit.
PointComponents OctreeComponents(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset, float voxel_m,
                                 std::size_t* skipped_non_finite);

}  // namespace romo::mapping::internal
