#include <gtest/gtest.h>

#include "romo/mapping/peers.hpp"
#include "romo/mapping/segmentation.hpp"
#include "romo/mapping/synthetic_scene.hpp"

namespace romo::mapping {
namespace {

// The bar for agreeing with pcl::EuclideanClusterExtraction.
constexpr double kMinAdjustedRandIndex = 0.98;

std::vector<int> Labels(const std::vector<std::vector<int>>& clusters, std::size_t n) {
  std::vector<int> labels(n, -1);
  for (std::size_t c = 0; c < clusters.size(); ++c)
    for (int i : clusters[c]) labels[i] = static_cast<int>(c);
  return labels;
}

TEST(PclAgreementTest, DfsBlobsMatchEuclideanClustersOnAParkingScene) {
  // Vehicle-scale scene (parked cars, pedestrians, poles; ground removed) at a density where the
  // 0.1 m tolerance connects every surface; leaf = tolerance is the matching setting (two points
  // closer than the tolerance always fall in neighbouring leaves).
  const SyntheticScene scene = MakeParkingScene(120000, 7);
  constexpr float kToleranceM = 0.1f;
  SegmentationParams params;
  params.leaf_size_m = kToleranceM;
  params.min_blob_points = 10;
  const Segmentation ours = SegmentBlobs(scene.cloud.xyz, params);
  const auto pcl = peers::PclEuclideanClusters(scene.cloud.xyz, kToleranceM, 10, 1 << 30);
  const double ari = peers::AdjustedRandIndex(Labels(ours.blobs, scene.cloud.size()), Labels(pcl, scene.cloud.size()));
  std::printf("romo blobs %zu, PCL clusters %zu, adjusted Rand index %.5f\n", ours.blobs.size(), pcl.size(), ari);
  EXPECT_GE(ari, kMinAdjustedRandIndex);
  EXPECT_EQ(ours.blobs.size(), scene.objects.size());
}

TEST(PclAgreementTest, AdjustedRandIndexIsOneForRelabelledPartitions) {
  EXPECT_DOUBLE_EQ(peers::AdjustedRandIndex({0, 0, 1, 1, 2}, {5, 5, 3, 3, 9}), 1.0);
  EXPECT_LT(peers::AdjustedRandIndex({0, 0, 1, 1}, {0, 1, 0, 1}), 0.0);
}

}  // namespace
}  // namespace romo::mapping
