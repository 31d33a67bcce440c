#include "romo/mapping/segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "internal/grid_components.hpp"
#include "internal/voxel_keys.hpp"
#include "romo/core/check.hpp"

namespace romo::mapping {
namespace {

void FailField(const char* field, double value, const char* rule) {
  std::ostringstream msg;
  msg << "SegmentationParams." << field << " = " << value << ": " << rule;
  Fail(msg.str());
}

float Diagonal(const Eigen::Matrix3Xf& xyz, const std::vector<int>& blob) {
  Eigen::Vector3f lo = xyz.col(blob.front()), hi = lo;
  for (int i : blob) {
    lo = lo.cwiseMin(xyz.col(i));
    hi = hi.cwiseMax(xyz.col(i));
  }
  return (hi - lo).norm();
}

/// Grid bytes allowed per point before a cloud counts as sparse: clearing and scanning a grid that
/// size costs about what the octree path's per-point sort and hashing do.
constexpr std::size_t kMaxGridBytesPerPoint = 32;
constexpr std::size_t kSmallGridBytes = std::size_t{1} << 20;  // always worth it

internal::PointComponents LabelPoints(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset,
                                      const SegmentationParams& params, float leaf_m,
                                      std::size_t* skipped_non_finite) {
  internal::FinitePoints finite = internal::GatherFinite(xyz, subset);
  *skipped_non_finite = finite.skipped_non_finite;
  const std::size_t bytes = internal::DenseGridBytes(finite, leaf_m);
  const std::size_t sparse_limit = kMaxGridBytesPerPoint * finite.indices.size() + kSmallGridBytes;
  if (bytes <= params.dense_grid_max_bytes && bytes <= sparse_limit) {
    return internal::DenseGridComponents(xyz, std::move(finite), leaf_m);
  }
  return internal::OctreeComponents(xyz, subset, leaf_m, skipped_non_finite);
}

void SegmentAtLeaf(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset,
                   const SegmentationParams& params, float leaf_m, int level, Segmentation* out) {
  std::size_t skipped = 0;
  const internal::PointComponents pc = LabelPoints(xyz, subset, params, leaf_m, &skipped);
  if (level == 0) {
    out->occupied_leaves = pc.occupied_voxels;
    out->skipped_non_finite = skipped;
  }
  const std::size_t components = pc.sizes.size();
  const auto kept = [&](std::size_t c) { return pc.sizes[c] >= static_cast<std::uint32_t>(params.min_blob_points); };
  std::vector<std::vector<int>> blobs(components);
  for (std::size_t c = 0; c < components; ++c) {
    if (kept(c)) blobs[c].reserve(pc.sizes[c]);
  }
  const std::size_t m = pc.indices.size();
  if (pc.ascending) {
    for (std::size_t k = 0; k < m; ++k) {
      if (kept(pc.labels[k])) blobs[pc.labels[k]].push_back(pc.indices[k]);
    }
  } else if (4 * m >= static_cast<std::size_t>(xyz.cols())) {
    // Scatter labels to points, then gather in index order: ascending lists without a sort.
    std::vector<std::int32_t> point_label(static_cast<std::size_t>(xyz.cols()), -1);
    for (std::size_t k = 0; k < m; ++k) point_label[pc.indices[k]] = static_cast<std::int32_t>(pc.labels[k]);
    for (std::size_t i = 0; i < point_label.size(); ++i) {
      const std::int32_t c = point_label[i];
      if (c >= 0 && kept(c)) blobs[c].push_back(static_cast<int>(i));
    }
  } else {
    for (std::size_t k = 0; k < m; ++k) {
      if (kept(pc.labels[k])) blobs[pc.labels[k]].push_back(pc.indices[k]);
    }
    for (auto& blob : blobs) std::sort(blob.begin(), blob.end());
  }
  for (std::size_t c = 0; c < components; ++c) {
    auto& blob = blobs[c];
    if (!kept(c)) {
      ++out->dropped_small;
      continue;
    }
    // Fig. 3.8: a blob too large for one object is probably several touching ones.
    if (params.max_object_extent_m > 0.f && level < params.max_refine_levels &&
        Diagonal(xyz, blob) > params.max_object_extent_m) {
      const std::size_t before = out->blobs.size();
      SegmentAtLeaf(xyz, &blob, params, leaf_m * params.refine_factor, level + 1, out);
      if (out->blobs.size() - before != 1) ++out->refined;
      continue;
    }
    if (blob.size() > static_cast<std::size_t>(params.max_blob_points)) {
      ++out->dropped_large;
      continue;
    }
    out->blobs.push_back(std::move(blob));
  }
}

}  // namespace

void SegmentationParams::Validate() const {
  if (!(std::isfinite(leaf_size_m) && leaf_size_m > 0.f)) FailField("leaf_size_m", leaf_size_m, "must be finite and > 0");
  if (min_blob_points < 1) FailField("min_blob_points", min_blob_points, "must be >= 1");
  if (max_blob_points < min_blob_points) FailField("max_blob_points", max_blob_points, "must be >= min_blob_points");
  if (!std::isfinite(max_object_extent_m)) FailField("max_object_extent_m", max_object_extent_m, "must be finite");
  if (!(refine_factor > 0.f && refine_factor < 1.f)) FailField("refine_factor", refine_factor, "must be in (0, 1)");
  if (max_refine_levels < 0) FailField("max_refine_levels", max_refine_levels, "must be >= 0");
}

Segmentation SegmentBlobs(const Eigen::Matrix3Xf& xyz, const SegmentationParams& params,
                          const std::vector<int>* subset) {
  params.Validate();
  Segmentation out;
  SegmentAtLeaf(xyz, subset, params, params.leaf_size_m, 0, &out);
  std::stable_sort(out.blobs.begin(), out.blobs.end(), [](const auto& a, const auto& b) {
    return a.size() != b.size() ? a.size() > b.size() : a.front() < b.front();
  });
  return out;
}

std::vector<int> BlobLabels(const Segmentation& segmentation, std::size_t n) {
  std::vector<int> labels(n, -1);
  for (std::size_t b = 0; b < segmentation.blobs.size(); ++b) {
    for (int i : segmentation.blobs[b]) {
      ROMO_THROW_UNLESS(i >= 0 && static_cast<std::size_t>(i) < n);
      labels[static_cast<std::size_t>(i)] = static_cast<int>(b);
    }
  }
  return labels;
}

}  // namespace romo::mapping
