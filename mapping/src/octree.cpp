#include "romo/mapping/octree.hpp"

#include <cmath>
#include <sstream>

#include "internal/voxel_keys.hpp"
#include "romo/core/check.hpp"

namespace romo::mapping {
namespace {

std::uint64_t HashCode(std::uint64_t code) {
  // Fibonacci hashing spreads neighbouring Morton codes over the table.
  return code * 0x9E3779B97F4A7C15ULL;
}

}  // namespace

VoxelOctree::VoxelOctree(float leaf_size_m) : leaf_size_m_(leaf_size_m) {
  if (!(std::isfinite(leaf_size_m) && leaf_size_m > 0.f)) {
    std::ostringstream msg;
    msg << "octree leaf_size_m must be finite and > 0, got " << leaf_size_m;
    Fail(msg.str());
  }
}

void VoxelOctree::Build(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset) {
  nodes_.clear();
  point_order_.clear();
  leaf_begin_.clear();
  hash_slots_.clear();
  hash_mask_ = 0;
  hash_shift_ = 64;
  first_leaf_node_ = 0;
  depth_ = 0;
  origin_.setZero();

  internal::FinitePoints finite = internal::GatherFinite(xyz, subset);
  skipped_non_finite_ = finite.skipped_non_finite;
  if (finite.indices.empty()) return;
  ROMO_THROW_UNLESS(finite.indices.size() < (std::size_t{1} << 31));

  origin_ = internal::SnappedOrigin(finite.lo, leaf_size_m_);
  depth_ = internal::VoxelDepthFor(origin_, finite.hi, leaf_size_m_, "octree");
  std::vector<std::uint64_t> codes = internal::VoxelCodes(xyz, finite.indices, origin_, leaf_size_m_);
  point_order_ = std::move(finite.indices);
  internal::RadixSortPairs(&codes, &point_order_, 3 * depth_);

  // Distinct codes are the leaves; leaf_begin_ marks where each one's points start.
  std::vector<std::uint64_t> leaf_codes;
  leaf_codes.reserve(codes.size() / 2 + 1);
  leaf_begin_.reserve(codes.size() / 2 + 2);
  for (std::size_t i = 0; i < codes.size(); ++i) {
    if (i == 0 || codes[i] != codes[i - 1]) {
      leaf_codes.push_back(codes[i]);
      leaf_begin_.push_back(static_cast<std::uint32_t>(i));
    }
  }
  leaf_begin_.push_back(static_cast<std::uint32_t>(codes.size()));
  leaf_begin_.shrink_to_fit();
  BuildLevels(leaf_codes);
  BuildLeafIndex();
}

void VoxelOctree::BuildLevels(const std::vector<std::uint64_t>& leaf_codes) {
  // levels[l] = distinct code prefixes at level l; child_start[l][j] = first child of node j in
  // levels[l + 1]. Built bottom-up, then laid out root first.
  std::vector<std::vector<std::uint64_t>> levels(static_cast<std::size_t>(depth_) + 1);
  std::vector<std::vector<std::uint32_t>> child_start(static_cast<std::size_t>(depth_) + 1);
  levels[static_cast<std::size_t>(depth_)] = leaf_codes;
  for (int l = depth_ - 1; l >= 0; --l) {
    const auto& below = levels[static_cast<std::size_t>(l) + 1];
    auto& here = levels[static_cast<std::size_t>(l)];
    auto& starts = child_start[static_cast<std::size_t>(l)];
    for (std::size_t j = 0; j < below.size(); ++j) {
      const std::uint64_t parent = below[j] >> 3;
      if (here.empty() || here.back() != parent) {
        here.push_back(parent);
        starts.push_back(static_cast<std::uint32_t>(j));
      }
    }
  }
  std::vector<std::size_t> offset(static_cast<std::size_t>(depth_) + 2, 0);
  for (int l = 0; l <= depth_; ++l) offset[l + 1] = offset[l] + levels[l].size();
  nodes_.resize(offset[depth_ + 1]);
  for (int l = 0; l <= depth_; ++l) {
    const auto& here = levels[l];
    for (std::size_t j = 0; j < here.size(); ++j) {
      Node& n = nodes_[offset[l] + j];
      n.code = here[j];
      n.level = static_cast<std::uint8_t>(l);
      if (l == depth_) {
        n.first_child = static_cast<std::uint32_t>(j);  // leaf slot
        n.child_count = 0;
      } else {
        const std::size_t begin = child_start[l][j];
        const std::size_t end = j + 1 < here.size() ? child_start[l][j + 1] : levels[l + 1].size();
        n.first_child = static_cast<std::uint32_t>(offset[l + 1] + begin);
        n.child_count = static_cast<std::uint8_t>(end - begin);
      }
    }
  }
  first_leaf_node_ = offset[depth_];
}

void VoxelOctree::BuildLeafIndex() {
  const std::size_t leaves = leaf_count();
  std::size_t size = 16;
  while (size < 2 * leaves) size <<= 1;
  hash_slots_.assign(size, -1);
  hash_mask_ = size - 1;
  hash_shift_ = 64;
  while ((std::size_t{1} << (64 - hash_shift_)) < size) --hash_shift_;
  for (std::size_t leaf = 0; leaf < leaves; ++leaf) {
    std::uint64_t slot = HashCode(nodes_[first_leaf_node_ + leaf].code) >> hash_shift_;
    while (hash_slots_[slot] >= 0) slot = (slot + 1) & hash_mask_;
    hash_slots_[slot] = static_cast<std::int32_t>(leaf);
  }
}

std::int64_t VoxelOctree::FindLeaf(const Eigen::Vector3i& key) const {
  if (hash_slots_.empty()) return -1;
  const int limit = 1 << depth_;
  if ((key.array() < 0).any() || (key.array() >= limit).any()) return -1;
  return FindLeafByCode(internal::Morton(static_cast<std::uint32_t>(key.x()),
                                         static_cast<std::uint32_t>(key.y()),
                                         static_cast<std::uint32_t>(key.z())));
}

std::int64_t VoxelOctree::FindLeafByCode(std::uint64_t code) const {
  if (hash_slots_.empty()) return -1;
  std::uint64_t slot = HashCode(code) >> hash_shift_;
  while (true) {
    const std::int32_t leaf = hash_slots_[slot];
    if (leaf < 0) return -1;
    if (nodes_[first_leaf_node_ + static_cast<std::size_t>(leaf)].code == code) return leaf;
    slot = (slot + 1) & hash_mask_;
  }
}

Eigen::Vector3i VoxelOctree::LeafKey(std::size_t leaf) const {
  ROMO_THROW_UNLESS(leaf < leaf_count());
  return internal::MortonDecode(nodes_[first_leaf_node_ + leaf].code);
}

std::size_t VoxelOctree::MemoryBytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) + point_order_.capacity() * sizeof(int) +
         leaf_begin_.capacity() * sizeof(std::uint32_t) + hash_slots_.capacity() * sizeof(std::int32_t);
}

}  // namespace romo::mapping
