#pragma once
/// Reference implementations romo is compared with (tests and `romo bench mapping`): PCL's
/// EuclideanClusterExtraction and OctoMap. Target romo::mapping_peers; PCL/OctoMap types stay in
/// its .cpp files.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace romo::mapping::peers {

/// pcl::EuclideanClusterExtraction (kd-tree) over @p xyz at @p tolerance_m; clusters as index
/// lists (ascending), largest first.
std::vector<std::vector<int>> PclEuclideanClusters(const Eigen::Matrix3Xf& xyz, float tolerance_m,
                                                   int min_cluster_size, int max_cluster_size);

/// pcl::SACSegmentation plane (SACMODEL_PLANE, RANSAC) at @p threshold_m: (a, b, c, d) unit normal
/// and the inlier count.
struct PclPlane {
  Eigen::Vector4f coefficients = Eigen::Vector4f::Zero();
  std::size_t inliers = 0;
};
PclPlane PclRansacPlane(const Eigen::Matrix3Xf& xyz, float threshold_m, int max_iterations);

struct OctomapFigures {
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  double root_size_m = 0;
  std::size_t memory_bytes = 0;
  double build_ms = 0;
};
/// Inserts every point of @p xyz as an occupied cell of an octomap::OcTree at @p resolution_m
/// (no ray casting: the same job as romo's octree build) and prunes nothing.
OctomapFigures OctomapBuild(const Eigen::Matrix3Xf& xyz, double resolution_m);

/// Adjusted Rand index of two labelings (-1 = unlabeled noise, treated as its own singletons).
double AdjustedRandIndex(const std::vector<int>& a, const std::vector<int>& b);

}  // namespace romo::mapping::peers
