#include "romo/mapping/segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "internal/voxel_keys.hpp"
#include "romo/core/check.hpp"
#include "romo/mapping/octree.hpp"

namespace romo::mapping {
namespace {

void FailField(const char* field, double value, const char* rule) {
  std::ostringstream msg;
  msg << "SegmentationParams." << field << " = " << value << ": " << rule;
  Fail(msg.str());
}

/// Leaf components by iterative DFS over the 26-neighbourhood; returns one label per leaf.
std::vector<int> LabelLeaves(const VoxelOctree& tree, int* component_count) {
  const std::size_t leaves = tree.leaf_count();
  std::vector<int> label(leaves, -1);
  std::vector<std::uint32_t> stack;
  stack.reserve(1024);
  const std::uint32_t limit = 1u << tree.depth();
  int next = 0;
  for (std::size_t seed = 0; seed < leaves; ++seed) {
    if (label[seed] >= 0) continue;
    label[seed] = next;
    stack.push_back(static_cast<std::uint32_t>(seed));
    while (!stack.empty()) {
      const std::uint32_t leaf = stack.back();
      stack.pop_back();
      const Eigen::Vector3i key = internal::MortonDecode(tree.LeafCode(leaf));
      // Spread each neighbouring coordinate once; the 26 codes are ORs of these.
      std::uint64_t sx[3], sy[3], sz[3];
      bool vx[3], vy[3], vz[3];
      for (int d = 0; d < 3; ++d) {
        const std::int64_t x = key.x() + d - 1, y = key.y() + d - 1, z = key.z() + d - 1;
        vx[d] = x >= 0 && x < limit;
        vy[d] = y >= 0 && y < limit;
        vz[d] = z >= 0 && z < limit;
        sx[d] = vx[d] ? internal::SpreadBits3(static_cast<std::uint64_t>(x)) : 0;
        sy[d] = vy[d] ? internal::SpreadBits3(static_cast<std::uint64_t>(y)) << 1 : 0;
        sz[d] = vz[d] ? internal::SpreadBits3(static_cast<std::uint64_t>(z)) << 2 : 0;
      }
      for (int dz = 0; dz < 3; ++dz) {
        if (!vz[dz]) continue;
        for (int dy = 0; dy < 3; ++dy) {
          if (!vy[dy]) continue;
          for (int dx = 0; dx < 3; ++dx) {
            if (!vx[dx] || (dx == 1 && dy == 1 && dz == 1)) continue;
            const std::int64_t n = tree.FindLeafByCode(sx[dx] | sy[dy] | sz[dz]);
            if (n < 0 || label[static_cast<std::size_t>(n)] >= 0) continue;
            label[static_cast<std::size_t>(n)] = next;
            stack.push_back(static_cast<std::uint32_t>(n));
          }
        }
      }
    }
    ++next;
  }
  *component_count = next;
  return label;
}

float Diagonal(const Eigen::Matrix3Xf& xyz, const std::vector<int>& blob) {
  Eigen::Vector3f lo = xyz.col(blob.front()), hi = lo;
  for (int i : blob) {
    lo = lo.cwiseMin(xyz.col(i));
    hi = hi.cwiseMax(xyz.col(i));
  }
  return (hi - lo).norm();
}

void SegmentAtLeaf(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset,
                   const SegmentationParams& params, float leaf_m, int level, Segmentation* out) {
  VoxelOctree tree(leaf_m);
  tree.Build(xyz, subset);
  if (level == 0) {
    out->occupied_leaves = tree.leaf_count();
    out->skipped_non_finite = tree.skipped_non_finite();
  }
  int components = 0;
  const std::vector<int> label = LabelLeaves(tree, &components);
  std::vector<std::size_t> sizes(static_cast<std::size_t>(components), 0);
  for (std::size_t leaf = 0; leaf < label.size(); ++leaf) sizes[label[leaf]] += tree.LeafPointCount(leaf);
  std::vector<std::vector<int>> blobs(static_cast<std::size_t>(components));
  for (int c = 0; c < components; ++c) {
    if (static_cast<int>(sizes[c]) >= params.min_blob_points) blobs[c].reserve(sizes[c]);
  }
  if (level == 0) {
    // Scatter labels to points, then gather in index order: ascending lists without a sort.
    std::vector<int> point_label(static_cast<std::size_t>(xyz.cols()), -1);
    for (std::size_t leaf = 0; leaf < label.size(); ++leaf) {
      for (const int* p = tree.LeafPointsBegin(leaf); p != tree.LeafPointsEnd(leaf); ++p) point_label[*p] = label[leaf];
    }
    for (std::size_t i = 0; i < point_label.size(); ++i) {
      const int c = point_label[i];
      if (c >= 0 && static_cast<int>(sizes[c]) >= params.min_blob_points) blobs[c].push_back(static_cast<int>(i));
    }
  } else {
    for (std::size_t leaf = 0; leaf < label.size(); ++leaf) {
      if (static_cast<int>(sizes[label[leaf]]) < params.min_blob_points) continue;
      blobs[label[leaf]].insert(blobs[label[leaf]].end(), tree.LeafPointsBegin(leaf), tree.LeafPointsEnd(leaf));
    }
    for (auto& blob : blobs) std::sort(blob.begin(), blob.end());
  }
  for (int c = 0; c < components; ++c) {
    auto& blob = blobs[c];
    if (static_cast<int>(sizes[c]) < params.min_blob_points) {
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
    if (static_cast<int>(blob.size()) > params.max_blob_points) {
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
