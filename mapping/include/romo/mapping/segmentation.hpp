#pragma once
/// Connected components over occupied voxels (octree leaves) by depth-first search
/// (26-neighbourhood), dissertation 3.2 / Fig. 3.8. A dense bit grid over the cloud's bounding box
/// when it fits dense_grid_max_bytes, else the octree; both give the same blobs. Works on a cloud
/// in any frame (vehicle or indoor camera).
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace romo::mapping {

struct SegmentationParams {
  /// Octree leaf edge, metres. Two points closer than this in every axis always join.
  float leaf_size_m = 0.1f;
  /// Blobs with fewer points are dropped (noise).
  int min_blob_points = 10;
  /// Blobs with more points are dropped (walls, unremoved ground), after refinement.
  int max_blob_points = std::numeric_limits<int>::max();
  /// A blob whose bounding-box diagonal exceeds this (metres) is implausibly large for one object:
  /// it is re-clustered at leaf_size_m * refine_factor (Fig. 3.8). <= 0 disables refinement.
  float max_object_extent_m = 0.f;
  /// Leaf shrink per refinement step, in (0, 1).
  float refine_factor = 0.5f;
  /// How many times a blob may be refined.
  int max_refine_levels = 1;
  /// Memory (bytes) the dense voxel grid over the cloud's bounding box may take (about 5/16 byte
  /// per cell); a larger or very sparse extent is labelled through the octree instead, with the
  /// same result. 0 always uses the octree.
  std::size_t dense_grid_max_bytes = std::size_t{64} << 20;

  /// @throws romo::Error naming the field and value when a field is out of range.
  void Validate() const;
};

struct Segmentation {
  /// One index list (into the input cloud, ascending) per blob; blobs sorted by size, largest first.
  std::vector<std::vector<int>> blobs;
  std::size_t occupied_leaves = 0;     ///< at the base leaf size
  std::size_t dropped_small = 0;       ///< blobs below min_blob_points
  std::size_t dropped_large = 0;       ///< blobs above max_blob_points
  std::size_t refined = 0;             ///< blobs re-clustered at a finer leaf
  std::size_t skipped_non_finite = 0;  ///< input points ignored
};

/// Segments the finite points of @p xyz (3 x N, metres), or only @p subset (e.g. the non-ground
/// points). Empty or all-non-finite input gives an empty result.
/// @throws romo::Error on invalid @p params or an out-of-range subset index.
Segmentation SegmentBlobs(const Eigen::Matrix3Xf& xyz, const SegmentationParams& params,
                          const std::vector<int>* subset = nullptr);

/// Per-point labels (-1 = in no blob) for @p n points: handy for comparisons and colouring.
std::vector<int> BlobLabels(const Segmentation& segmentation, std::size_t n);

}  // namespace romo::mapping
