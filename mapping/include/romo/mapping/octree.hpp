#pragma once
/// romo's own voxel octree (the dissertation coded its own too, for speed). Built in bulk from a
/// cloud: points are keyed by the Morton code of their leaf voxel, radix-sorted, and every level
/// of the tree is the set of distinct code prefixes — flat arrays with integer indices, no
/// per-point or per-node allocation. The root grows (doubles) from one leaf until it covers the
/// cloud. Leaves keep a contiguous range of point indices; leaf lookup by voxel key is O(1).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace romo::mapping {

class VoxelOctree {
 public:
  /// Largest leaf coordinate per axis (21-bit Morton lanes).
  static constexpr int kMaxDepth = 21;

  struct Node {
    std::uint64_t code = 0;        ///< Morton code of the node at its level
    std::uint32_t first_child = 0; ///< index of the first child in nodes() (leaves: first leaf slot)
    std::uint8_t child_count = 0;  ///< children stored contiguously after first_child
    std::uint8_t level = 0;        ///< 0 = root, depth() = leaf
  };

  /// @throws romo::Error when @p leaf_size_m is not finite and > 0.
  explicit VoxelOctree(float leaf_size_m);

  /// Builds the tree from the finite points of @p xyz (3 x N, metres), or only from @p subset
  /// (indices into xyz). Non-finite points are skipped and counted. Replaces any earlier content.
  /// @throws romo::Error when the cloud's extent needs more than kMaxDepth levels at this leaf
  ///         size (message names extent and leaf), or a subset index is out of range.
  void Build(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset = nullptr);

  float leaf_size_m() const { return leaf_size_m_; }
  /// Levels below the root (root covers 2^depth leaves per axis).
  int depth() const { return depth_; }
  /// Edge length of the root cube, metres.
  float root_size_m() const { return leaf_size_m_ * static_cast<float>(1u << depth_); }
  /// Minimum corner of the root cube, metres.
  const Eigen::Vector3f& origin() const { return origin_; }
  /// All nodes, level by level (root first); leaves are the last leaf_count() entries.
  const std::vector<Node>& nodes() const { return nodes_; }
  std::size_t node_count() const { return nodes_.size(); }
  std::size_t leaf_count() const { return leaf_begin_.empty() ? 0 : leaf_begin_.size() - 1; }
  /// Finite points inserted.
  std::size_t point_count() const { return point_order_.size(); }
  std::size_t skipped_non_finite() const { return skipped_non_finite_; }
  /// Bytes held by the tree's arrays (capacity, i.e. what it really occupies).
  std::size_t MemoryBytes() const;

  /// Integer voxel coordinates of leaf @p leaf (0 <= leaf < leaf_count()).
  Eigen::Vector3i LeafKey(std::size_t leaf) const;
  /// Point indices (into the cloud given to Build) of leaf @p leaf: [begin, end).
  const int* LeafPointsBegin(std::size_t leaf) const { return point_order_.data() + leaf_begin_[leaf]; }
  const int* LeafPointsEnd(std::size_t leaf) const { return point_order_.data() + leaf_begin_[leaf + 1]; }
  std::size_t LeafPointCount(std::size_t leaf) const { return leaf_begin_[leaf + 1] - leaf_begin_[leaf]; }
  /// Leaf index at integer voxel coordinates @p key, or -1 when that voxel is empty / outside.
  std::int64_t FindLeaf(const Eigen::Vector3i& key) const;
  /// Morton code of leaf @p leaf (x in bits 0,3,6..., y in 1,4,..., z in 2,5,...).
  std::uint64_t LeafCode(std::size_t leaf) const { return nodes_[first_leaf_node_ + leaf].code; }
  /// Leaf index with Morton code @p code (coordinates already known to be inside), or -1.
  std::int64_t FindLeafByCode(std::uint64_t code) const;

  /// Depth-first traversal from the root: calls @p visit(const Node&, std::size_t node_index) for
  /// every node, children in Morton order. Iterative (explicit stack), no allocation per node.
  template <typename Visitor>
  void TraverseDepthFirst(Visitor&& visit) const;

 private:
  void BuildLevels(const std::vector<std::uint64_t>& leaf_codes);
  void BuildLeafIndex();

  float leaf_size_m_;
  int depth_ = 0;
  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  std::vector<Node> nodes_;
  std::size_t first_leaf_node_ = 0;
  std::vector<int> point_order_;            // point indices sorted by leaf
  std::vector<std::uint32_t> leaf_begin_;   // leaf_count()+1 offsets into point_order_
  std::vector<std::int32_t> hash_slots_;    // open-addressing table: leaf index or -1
  std::uint64_t hash_mask_ = 0;
  int hash_shift_ = 64;
  std::size_t skipped_non_finite_ = 0;
};

template <typename Visitor>
void VoxelOctree::TraverseDepthFirst(Visitor&& visit) const {
  if (nodes_.empty()) return;
  std::vector<std::uint32_t> stack;
  stack.reserve(static_cast<std::size_t>(8 * (depth_ + 1)));
  stack.push_back(0);
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    const Node& n = nodes_[i];
    visit(n, static_cast<std::size_t>(i));
    if (n.level == depth_) continue;
    // Push in reverse so children pop in Morton order.
    for (int c = n.child_count - 1; c >= 0; --c) stack.push_back(n.first_child + static_cast<std::uint32_t>(c));
  }
}

}  // namespace romo::mapping
