#include "internal/grid_components.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "romo/core/check.hpp"
#include "romo/mapping/octree.hpp"

namespace romo::mapping::internal {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "bit-plane loads assume little-endian words");

constexpr float kMaxCoord = static_cast<float>((1u << 21) - 1);

/// Voxel coordinate along one axis, equal to VoxelCodes' clamp(floor((p - o) * inv), 0, max):
/// below 0 both give 0, and from 0 up truncation is floor. Clamping before the conversion keeps it
/// in range; baseline x86-64 has no cheap floor (no SSE4.1), truncation is one instruction.
inline std::uint32_t Coord(float p, float origin, float inv, float max_coord) {
  return static_cast<std::uint32_t>(std::min(std::max((p - origin) * inv, 0.f), max_coord));
}

// SWAR popcount: the build targets baseline x86-64, which has no POPCNT instruction.
inline std::uint32_t Popcount(std::uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ULL);
  x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fULL;
  return static_cast<std::uint32_t>((x * 0x0101010101010101ULL) >> 56);
}

/// Padded grid geometry: voxel (x, y, z) lives at bit (x+1) + nx ((y+1) + ny (z+1)), so every
/// occupied voxel has all 26 neighbours inside the grid and the DFS needs no bounds tests.
struct GridShape {
  Eigen::Vector3f origin;
  float inv = 0.f;
  std::uint32_t max_coord[3] = {0, 0, 0};
  std::uint64_t nx = 0, ny = 0, nz = 0;
  std::uint64_t cells = 0;
  std::uint64_t words = 0;  // 64-bit words per bit plane, one spare for the 8-byte loads
};

GridShape ShapeFor(const FinitePoints& finite, float voxel_m) {
  GridShape g;
  g.origin = SnappedOrigin(finite.lo, voxel_m);
  g.inv = 1.f / voxel_m;
  // floor((p - o) * inv) is monotonic in p, so hi holds every axis' largest coordinate.
  for (int a = 0; a < 3; ++a) {
    g.max_coord[a] = Coord(finite.hi[a], g.origin[a], g.inv, kMaxCoord);
  }
  g.nx = std::uint64_t{g.max_coord[0]} + 3;
  g.ny = std::uint64_t{g.max_coord[1]} + 3;
  g.nz = std::uint64_t{g.max_coord[2]} + 3;
  g.cells = g.nx * g.ny * g.nz;  // < 2^66 cannot overflow: each factor <= 2^21 + 2
  g.words = g.cells / 64 + 2;
  return g;
}

/// The three bits x-1, x, x+1 of the row starting at bit @p b (i.e. b = cell - 1).
inline std::uint32_t ThreeBits(const unsigned char* plane, std::uint64_t b) {
  std::uint64_t w;
  std::memcpy(&w, plane + (b >> 3), sizeof(w));
  return static_cast<std::uint32_t>(w >> (b & 7)) & 7u;
}

}  // namespace

std::size_t DenseGridBytes(const FinitePoints& finite, float voxel_m) {
  if (finite.indices.empty()) return 0;
  const GridShape g = ShapeFor(finite, voxel_m);
  // Cells are indexed in 32 bits (one per point); ranks count at most the points.
  if (g.cells >= (std::uint64_t{1} << 32) - 128) return std::numeric_limits<std::size_t>::max();
  return static_cast<std::size_t>(g.words * (2 * sizeof(std::uint64_t) + sizeof(std::uint32_t)));
}

PointComponents DenseGridComponents(const Eigen::Matrix3Xf& xyz, FinitePoints finite, float voxel_m) {
  PointComponents out;
  if (finite.indices.empty()) return out;
  // Same extent rule and message as the octree, so both paths fail alike.
  const GridShape g = ShapeFor(finite, voxel_m);
  VoxelDepthFor(g.origin, finite.hi, voxel_m, "octree");
  ROMO_DEMAND(g.cells < (std::uint64_t{1} << 32) - 128);

  const std::size_t m = finite.indices.size();
  const int* idx = finite.indices.data();
  const float* p = xyz.data();
  const float ox = g.origin.x(), oy = g.origin.y(), oz = g.origin.z(), inv = g.inv;
  const float mx = static_cast<float>(g.max_coord[0]), my = static_cast<float>(g.max_coord[1]),
              mz = static_cast<float>(g.max_coord[2]);
  const std::uint64_t nx = g.nx, nxy = g.nx * g.ny;

  // 1. Voxel bit of every point; `cell` later becomes the point's label in place.
  std::vector<std::uint64_t> occupied(g.words, 0);
  std::vector<std::uint32_t> cell(m);
  bool ascending = true;
  int previous = -1;
  for (std::size_t k = 0; k < m; ++k) {
    const int i = idx[k];
    ascending &= i > previous;
    previous = i;
    const float* q = p + 3 * static_cast<std::size_t>(i);
    const std::uint64_t c = (Coord(q[0], ox, inv, mx) + 1) + nx * (Coord(q[1], oy, inv, my) + 1) +
                            nxy * (Coord(q[2], oz, inv, mz) + 1);
    cell[k] = static_cast<std::uint32_t>(c);
    occupied[c >> 6] |= std::uint64_t{1} << (c & 63);
  }

  // 2. Dense voxel numbers: rank[w] = occupied voxels before word w.
  std::vector<std::uint32_t> rank(g.words);
  std::uint32_t voxels = 0;
  for (std::uint64_t w = 0; w < g.words; ++w) {
    rank[w] = voxels;
    voxels += Popcount(occupied[w]);
  }
  const auto rank_of = [&](std::uint64_t c) {
    const std::uint64_t below = (std::uint64_t{1} << (c & 63)) - 1;
    return rank[c >> 6] + Popcount(occupied[c >> 6] & below);
  };
  out.occupied_voxels = voxels;

  // 3. Iterative DFS over the unvisited plane; seeds in cell order. Each popped voxel tests its 9
  // rows of three x-neighbours with one load per row.
  std::vector<std::uint64_t> unvisited = occupied;
  unsigned char* plane = reinterpret_cast<unsigned char*>(unvisited.data());
  std::int64_t row_start[9];
  int r = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      row_start[r++] = dz * static_cast<std::int64_t>(nxy) + dy * static_cast<std::int64_t>(nx) - 1;
    }
  }
  std::vector<std::uint32_t> component(voxels);
  std::vector<std::uint32_t> stack;
  stack.reserve(4096);
  std::uint32_t next = 0;
  for (std::uint64_t w = 0; w < g.words; ++w) {
    while (unvisited[w] != 0) {
      const std::uint64_t seed = w * 64 + static_cast<std::uint64_t>(__builtin_ctzll(unvisited[w]));
      unvisited[w] &= unvisited[w] - 1;
      component[rank_of(seed)] = next;
      stack.push_back(static_cast<std::uint32_t>(seed));
      while (!stack.empty()) {
        const std::uint64_t c = stack.back();
        stack.pop_back();
        for (const std::int64_t start : row_start) {
          const std::uint64_t b = c + static_cast<std::uint64_t>(start);
          std::uint32_t bits = ThreeBits(plane, b);
          while (bits != 0) {
            const std::uint64_t n = b + static_cast<std::uint64_t>(__builtin_ctz(bits));
            bits &= bits - 1;
            plane[n >> 3] &= static_cast<unsigned char>(~(1u << (n & 7)));
            component[rank_of(n)] = next;
            stack.push_back(static_cast<std::uint32_t>(n));
          }
        }
      }
      ++next;
    }
  }

  // 4. Point labels and component sizes.
  out.sizes.assign(next, 0);
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t label = component[rank_of(cell[k])];
    cell[k] = label;
    ++out.sizes[label];
  }
  out.labels = std::move(cell);
  out.indices = std::move(finite.indices);
  out.ascending = ascending;
  return out;
}

PointComponents OctreeComponents(const Eigen::Matrix3Xf& xyz, const std::vector<int>* subset, float voxel_m,
                                 std::size_t* skipped_non_finite) {
  VoxelOctree tree(voxel_m);
  tree.Build(xyz, subset);
  *skipped_non_finite = tree.skipped_non_finite();
  PointComponents out;
  const std::size_t leaves = tree.leaf_count();
  out.occupied_voxels = leaves;
  if (leaves == 0) return out;
  // DFS over the leaves, 26 neighbours each found by a hash lookup of its Morton code.
  std::vector<std::int32_t> label(leaves, -1);
  std::vector<std::uint32_t> stack;
  const std::int64_t limit = std::int64_t{1} << tree.depth();
  std::int32_t next = 0;
  for (std::size_t seed = 0; seed < leaves; ++seed) {
    if (label[seed] >= 0) continue;
    label[seed] = next;
    stack.push_back(static_cast<std::uint32_t>(seed));
    while (!stack.empty()) {
      const std::uint32_t leaf = stack.back();
      stack.pop_back();
      const Eigen::Vector3i key = MortonDecode(tree.LeafCode(leaf));
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const std::int64_t x = key.x() + dx, y = key.y() + dy, z = key.z() + dz;
            if ((dx == 0 && dy == 0 && dz == 0) || x < 0 || y < 0 || z < 0 || x >= limit || y >= limit ||
                z >= limit) {
              continue;
            }
            const std::int64_t n = tree.FindLeafByCode(
                Morton(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)));
            if (n < 0 || label[static_cast<std::size_t>(n)] >= 0) continue;
            label[static_cast<std::size_t>(n)] = next;
            stack.push_back(static_cast<std::uint32_t>(n));
          }
        }
      }
    }
    ++next;
  }
  out.sizes.assign(static_cast<std::size_t>(next), 0);
  out.indices.assign(tree.LeafPointsBegin(0), tree.LeafPointsEnd(leaves - 1));
  out.labels.resize(out.indices.size());
  std::size_t k = 0;
  for (std::size_t leaf = 0; leaf < leaves; ++leaf) {
    const auto l = static_cast<std::uint32_t>(label[leaf]);
    const std::size_t count = tree.LeafPointCount(leaf);
    std::fill_n(out.labels.begin() + static_cast<std::ptrdiff_t>(k), count, l);
    out.sizes[l] += static_cast<std::uint32_t>(count);
    k += count;
  }
  out.ascending = std::is_sorted(out.indices.begin(), out.indices.end());
  return out;
}

}  // namespace romo::mapping::internal
