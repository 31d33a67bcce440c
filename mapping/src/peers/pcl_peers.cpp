// The only mapping translation unit that includes PCL (slow to compile).
#include <algorithm>

#include <pcl/ModelCoefficients.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "romo/mapping/peers.hpp"

namespace romo::mapping::peers {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr ToPcl(const Eigen::Matrix3Xf& xyz) {
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(static_cast<std::size_t>(xyz.cols()));
  for (Eigen::Index i = 0; i < xyz.cols(); ++i) {
    (*cloud)[static_cast<std::size_t>(i)] = pcl::PointXYZ(xyz(0, i), xyz(1, i), xyz(2, i));
  }
  return cloud;
}

}  // namespace

std::vector<std::vector<int>> PclEuclideanClusters(const Eigen::Matrix3Xf& xyz, float tolerance_m,
                                                   int min_cluster_size, int max_cluster_size) {
  const auto cloud = ToPcl(xyz);
  auto tree = pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
  tree->setInputCloud(cloud);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ece;
  ece.setClusterTolerance(tolerance_m);
  ece.setMinClusterSize(min_cluster_size);
  ece.setMaxClusterSize(max_cluster_size);
  ece.setSearchMethod(tree);
  ece.setInputCloud(cloud);
  std::vector<pcl::PointIndices> found;
  ece.extract(found);
  std::vector<std::vector<int>> out;
  out.reserve(found.size());
  for (auto& c : found) {
    std::vector<int> idx(c.indices.begin(), c.indices.end());
    std::sort(idx.begin(), idx.end());
    out.push_back(std::move(idx));
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return out;
}

PclPlane PclRansacPlane(const Eigen::Matrix3Xf& xyz, float threshold_m, int max_iterations) {
  const auto cloud = ToPcl(xyz);
  pcl::SACSegmentation<pcl::PointXYZ> seg;
  seg.setModelType(pcl::SACMODEL_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setDistanceThreshold(threshold_m);
  seg.setMaxIterations(max_iterations);
  seg.setOptimizeCoefficients(true);
  seg.setInputCloud(cloud);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  seg.segment(inliers, coefficients);
  PclPlane out;
  if (coefficients.values.size() == 4) {
    out.coefficients = Eigen::Vector4f(coefficients.values[0], coefficients.values[1], coefficients.values[2],
                                       coefficients.values[3]);
  }
  out.inliers = inliers.indices.size();
  return out;
}

}  // namespace romo::mapping::peers
