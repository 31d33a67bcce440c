#include <chrono>

#include <octomap/OcTree.h>

#include "romo/mapping/peers.hpp"

namespace romo::mapping::peers {

OctomapFigures OctomapBuild(const Eigen::Matrix3Xf& xyz, double resolution_m) {
  const auto start = std::chrono::steady_clock::now();
  octomap::OcTree tree(resolution_m);
  for (Eigen::Index i = 0; i < xyz.cols(); ++i) {
    // lazy_eval: inner nodes are updated once at the end, OctoMap's fast path for bulk inserts.
    tree.updateNode(octomap::point3d(xyz(0, i), xyz(1, i), xyz(2, i)), true, true);
  }
  tree.updateInnerOccupancy();
  const auto stop = std::chrono::steady_clock::now();
  OctomapFigures out;
  out.build_ms = std::chrono::duration<double, std::milli>(stop - start).count();
  out.nodes = tree.calcNumNodes();
  out.leaves = tree.getNumLeafNodes();
  out.root_size_m = resolution_m * static_cast<double>(1u << tree.getTreeDepth());
  out.memory_bytes = tree.memoryUsage();
  return out;
}

}  // namespace romo::mapping::peers
