#include "internal/voxel_keys.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "romo/core/check.hpp"

namespace romo::mapping::internal {

FinitePoints GatherFinite(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset) {
  FinitePoints out;
  const std::size_t n = subset ? subset->size() : static_cast<std::size_t>(xyz.cols());
  out.indices.resize(n);
  int* kept = out.indices.data();
  std::size_t count = 0;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  float lo_x = kInf, lo_y = kInf, lo_z = kInf, hi_x = -kInf, hi_y = -kInf, hi_z = -kInf;
  const float* p = xyz.data();
  for (std::size_t k = 0; k < n; ++k) {
    const int i = subset ? (*subset)[k] : static_cast<int>(k);
    if (subset && (i < 0 || i >= xyz.cols())) {
      std::ostringstream msg;
      msg << "point subset index " << i << " out of range for a cloud of " << xyz.cols() << " points";
      Fail(msg.str());
    }
    const float* q = p + 3 * static_cast<std::size_t>(i);
    const float x = q[0], y = q[1], z = q[2];
    // v - v is 0 for finite v and NaN for NaN or +-inf: one test for all three.
    if (!((x - x) + (y - y) + (z - z) == 0.f)) continue;
    kept[count++] = i;
    lo_x = std::min(lo_x, x);
    lo_y = std::min(lo_y, y);
    lo_z = std::min(lo_z, z);
    hi_x = std::max(hi_x, x);
    hi_y = std::max(hi_y, y);
    hi_z = std::max(hi_z, z);
  }
  out.indices.resize(count);
  out.skipped_non_finite = n - count;
  if (count > 0) {
    out.lo = Eigen::Vector3f(lo_x, lo_y, lo_z);
    out.hi = Eigen::Vector3f(hi_x, hi_y, hi_z);
  }
  return out;
}

Eigen::Vector3f SnappedOrigin(const Eigen::Vector3f& lo, float voxel_m) {
  return ((lo.array() / voxel_m).floor() * voxel_m).matrix();
}

std::vector<std::uint64_t> VoxelCodes(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices,
                                      const Eigen::Vector3f& origin, float voxel_m) {
  std::vector<std::uint64_t> codes(indices.size());
  const float inv = 1.f / voxel_m;
  constexpr float kMaxCoord = static_cast<float>((1u << 21) - 1);
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const int i = indices[k];
    // Clamp guards float rounding at the far edge; the extent was checked by VoxelDepthFor.
    const auto coord = [&](int axis) {
      const float c = std::floor((xyz(axis, i) - origin[axis]) * inv);
      return static_cast<std::uint32_t>(std::clamp(c, 0.f, kMaxCoord));
    };
    codes[k] = Morton(coord(0), coord(1), coord(2));
  }
  return codes;
}

int VoxelDepthFor(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float voxel_m, const char* what) {
  const double extent = static_cast<double>((hi - lo).maxCoeff());
  const double cells = std::floor(extent / voxel_m) + 1.0;
  int depth = 0;
  // The root grows by doubling from one voxel until it covers the extent.
  while (std::ldexp(1.0, depth) < cells) {
    ++depth;
    if (depth > 21) {
      std::ostringstream msg;
      msg << what << ": cloud extent " << extent << " m needs more than 2^21 voxels of " << voxel_m
          << " m per axis; use a larger voxel/leaf size";
      Fail(msg.str());
    }
  }
  return depth;
}

void RadixSortPairs(std::vector<std::uint64_t>* codes, std::vector<int>* values, int key_bits) {
  ROMO_DEMAND(codes->size() == values->size());
  constexpr int kDigitBits = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  const std::size_t n = codes->size();
  if (n < 2 || key_bits <= 0) return;
  std::vector<std::uint64_t> codes_tmp(n);
  std::vector<int> values_tmp(n);
  std::vector<std::size_t> count(kBuckets);
  for (int shift = 0; shift < key_bits; shift += kDigitBits) {
    std::fill(count.begin(), count.end(), 0);
    const std::uint64_t* src = codes->data();
    for (std::size_t i = 0; i < n; ++i) ++count[(src[i] >> shift) & (kBuckets - 1)];
    if (count[(src[0] >> shift) & (kBuckets - 1)] == n) continue;  // digit constant: nothing moves
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t here = c;
      c = sum;
      sum += here;
    }
    const int* vsrc = values->data();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t dst = count[(src[i] >> shift) & (kBuckets - 1)]++;
      codes_tmp[dst] = src[i];
      values_tmp[dst] = vsrc[i];
    }
    codes->swap(codes_tmp);
    values->swap(values_tmp);
  }
}

}  // namespace romo::mapping::internal
