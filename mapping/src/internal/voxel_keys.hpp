#pragma once
// Shared voxel keying for the octree, segmentation and fusion: finite bounds, 21-bit Morton
// codes and an LSD radix sort of (code, point index) pairs.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace romo::mapping::internal {

/// Indices of the finite points of @p xyz (all, or those in @p subset) and their bounds.
/// @throws romo::Error when a subset index is out of range.
struct FinitePoints {
  std::vector<int> indices;
  Eigen::Vector3f lo = Eigen::Vector3f::Zero();
  Eigen::Vector3f hi = Eigen::Vector3f::Zero();
  std::size_t skipped_non_finite = 0;
};
FinitePoints GatherFinite(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset);

/// Spreads the low 21 bits of @p v so bit i moves to bit 3i.
inline std::uint64_t SpreadBits3(std::uint64_t v) {
  v &= 0x1fffffULL;
  v = (v | (v << 32)) & 0x1f00000000ffffULL;
  v = (v | (v << 16)) & 0x1f0000ff0000ffULL;
  v = (v | (v << 8)) & 0x100f00f00f00f00fULL;
  v = (v | (v << 4)) & 0x10c30c30c30c30c3ULL;
  v = (v | (v << 2)) & 0x1249249249249249ULL;
  return v;
}
inline std::uint32_t CompactBits3(std::uint64_t v) {
  v &= 0x1249249249249249ULL;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ULL;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00fULL;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffULL;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffULL;
  v = (v ^ (v >> 32)) & 0x1fffffULL;
  return static_cast<std::uint32_t>(v);
}
inline std::uint64_t Morton(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return SpreadBits3(x) | (SpreadBits3(y) << 1) | (SpreadBits3(z) << 2);
}
inline Eigen::Vector3i MortonDecode(std::uint64_t code) {
  return {static_cast<int>(CompactBits3(code)), static_cast<int>(CompactBits3(code >> 1)),
          static_cast<int>(CompactBits3(code >> 2))};
}

/// @p lo snapped down to a multiple of @p voxel_m: voxel boundaries stay at fixed positions of the
/// frame whatever the cloud's extent, so the same surface gets the same voxels frame to frame.
Eigen::Vector3f SnappedOrigin(const Eigen::Vector3f& lo, float voxel_m);

/// Morton codes of the voxels (edge @p voxel_m, grid origin @p origin) of points @p indices.
/// Coordinates must fit 21 bits; the caller checks the extent first (VoxelDepthFor).
std::vector<std::uint64_t> VoxelCodes(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices,
                                      const Eigen::Vector3f& origin, float voxel_m);

/// Smallest depth D with 2^D voxels covering [lo, hi] from lo.
/// @throws romo::Error (naming extent and voxel size) when D would exceed 21.
int VoxelDepthFor(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float voxel_m, const char* what);

/// Sorts @p codes ascending (stable) and permutes @p values alongside; only the low @p key_bits
/// bits are looked at.
void RadixSortPairs(std::vector<std::uint64_t>* codes, std::vector<int>* values, int key_bits);

}  // namespace romo::mapping::internal
