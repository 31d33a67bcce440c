#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/mapping/fusion.hpp"

namespace romo::mapping {
namespace {

constexpr float kPi = 3.14159265f;

/// Rig mounted like the RoMo sample calibration: at (x, y, 1.2 m), yawed, pitched down 15 deg;
/// rig frame = optical (x right, y down, z forward).
Eigen::Isometry3f Mount(float x, float y, float yaw_rad) {
  Eigen::Matrix3f optical_to_body;  // body: x forward, y left, z up
  optical_to_body << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::AngleAxisf(yaw_rad, Eigen::Vector3f::UnitZ()).toRotationMatrix() *
               Eigen::AngleAxisf(15.f * kPi / 180.f, Eigen::Vector3f::UnitY()).toRotationMatrix() * optical_to_body;
  T.translation() = Eigen::Vector3f(x, y, 1.2f);
  return T;
}

/// What rig @p T_vehicle_rig sees of vehicle-frame points @p world at a vehicle displacement.
PointCloud Observe(const Eigen::Matrix3Xf& vehicle_pts, const Eigen::Isometry3f& T_vehicle_rig,
                   const Eigen::Isometry3f& T_ref_then, float sigma) {
  PointCloud c;
  c.Resize(static_cast<std::size_t>(vehicle_pts.cols()));
  const Eigen::Isometry3f T_rig_ref = (T_ref_then * T_vehicle_rig).inverse();
  for (Eigen::Index i = 0; i < vehicle_pts.cols(); ++i) {
    c.xyz.col(i) = T_rig_ref * Eigen::Vector3f(vehicle_pts.col(i));
    c.sigma_z_m[i] = sigma;
  }
  return c;
}

TEST(FusionTest, MotionCompensationPutsAStaticPointWhereItWasAtTheReferenceInstant) {
  // Vehicle at 10 m/s turning at 0.5 rad/s; the front rig captures 40 ms after the reference and
  // the rear rig 30 ms before. Both see the same static points: after fusion they coincide.
  VehicleMotion motion{10.f, 0.5f, 1'000'000'000};
  Eigen::Matrix3Xf pts(3, 2);
  pts.col(0) = Eigen::Vector3f(8.f, 1.f, 0.5f);
  pts.col(1) = Eigen::Vector3f(-7.f, -2.f, 1.0f);
  RigCloud front{0, motion.reference_stamp_ns + 40'000'000, Mount(1.4f, 0.f, 0.f), {}};
  RigCloud rear{3, motion.reference_stamp_ns - 30'000'000, Mount(-1.4f, 0.f, kPi), {}};
  front.cloud = Observe(pts.leftCols(1), front.T_vehicle_rig, VehicleDisplacement(motion, front.stamp_ns), 0.01f);
  rear.cloud = Observe(pts.rightCols(1), rear.T_vehicle_rig, VehicleDisplacement(motion, rear.stamp_ns), 0.01f);
  FusionParams params;
  params.overlap_voxel_m = 0.f;
  std::vector<int> rig_ids;
  const PointCloud fused = FuseRigClouds({front, rear}, motion, params, nullptr, &rig_ids);
  ASSERT_EQ(fused.size(), 2u);
  EXPECT_EQ(rig_ids, (std::vector<int>{0, 3}));  // which rig saw each point (its viewpoint)
  constexpr float kPositionToleranceM = 1e-4f;  // float rounding over ~10 m
  EXPECT_LT((fused.xyz.col(0) - pts.col(0)).norm(), kPositionToleranceM);
  EXPECT_LT((fused.xyz.col(1) - pts.col(1)).norm(), kPositionToleranceM);
  // Without compensation the front point would be off by about v * dt = 0.4 m.
  const PointCloud naive = FuseRigClouds({front, rear}, VehicleMotion{0.f, 0.f, motion.reference_stamp_ns}, params);
  EXPECT_GT((naive.xyz.col(0) - pts.col(0)).norm(), 0.35f);
}

TEST(FusionTest, VehicleDisplacementIsTheExactArc) {
  const VehicleMotion m{5.f, kPi / 2.f, 0};  // quarter turn in 1 s on a radius of 10/pi m
  const Eigen::Isometry3f T = VehicleDisplacement(m, 1'000'000'000);
  const float r = 5.f / (kPi / 2.f);
  EXPECT_NEAR(T.translation().x(), r, 1e-4f);
  EXPECT_NEAR(T.translation().y(), r, 1e-4f);
  EXPECT_NEAR(std::atan2(T.linear()(1, 0), T.linear()(0, 0)), kPi / 2.f, 1e-5f);
}

TEST(FusionTest, OverlapSeenByTwoRigsIsCountedOnceKeepingTheLowerSigma) {
  // A wall patch seen by front (sigma 0.02) and right_front (sigma 0.05) rigs, plus points only
  // the front rig sees: the overlap keeps only the front's points there. Points sit off the
  // 0.05 m voxel boundaries, where the two copies of a point differ only by float rounding.
  Eigen::Matrix3Xf shared(3, 400), only_front(3, 100);
  for (int i = 0; i < 400; ++i) shared.col(i) = Eigen::Vector3f(6.013f, -2.0025f + 0.01f * i, 1.027f);
  for (int i = 0; i < 100; ++i) only_front.col(i) = Eigen::Vector3f(6.013f, 3.0025f + 0.01f * i, 1.027f);
  Eigen::Matrix3Xf front_pts(3, 500);
  front_pts << shared, only_front;
  const VehicleMotion still{0.f, 0.f, 0};
  RigCloud front{0, 0, Mount(1.4f, 0.f, 0.f), {}};
  RigCloud right{5, 0, Mount(0.7f, -0.8f, -kPi / 3.f), {}};
  front.cloud = Observe(front_pts, front.T_vehicle_rig, Eigen::Isometry3f::Identity(), 0.02f);
  right.cloud = Observe(shared, right.T_vehicle_rig, Eigen::Isometry3f::Identity(), 0.05f);
  FusionParams params;
  params.overlap_voxel_m = 0.05f;
  FusionStats stats;
  std::vector<int> rig_ids;
  const PointCloud fused = FuseRigClouds({front, right}, still, params, &stats, &rig_ids);
  EXPECT_EQ(stats.input_points, 900u);
  EXPECT_EQ(fused.size(), 500u);  // the right rig's 400 duplicates are gone
  EXPECT_EQ(rig_ids, std::vector<int>(500, 0));  // every kept point is the front rig's
  EXPECT_EQ(stats.thinned, 400u);
  for (float s : fused.sigma_z_m) EXPECT_FLOAT_EQ(s, 0.02f);
}

TEST(FusionTest, BadInputIsRejectedWithTheRigNamed) {
  RigCloud stale{4, 5'000'000'000, Eigen::Isometry3f::Identity(), {}};
  stale.cloud.PushBack(Eigen::Vector3f(1, 2, 3));
  try {
    FuseRigClouds({stale}, VehicleMotion{0.f, 0.f, 0}, FusionParams{});
    FAIL() << "stale rig accepted";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("rig 4"), std::string::npos) << e.what();
  }
  RigCloud broken{2, 0, Eigen::Isometry3f::Identity(), {}};
  broken.cloud.xyz.resize(3, 3);
  EXPECT_THROW(FuseRigClouds({broken}, VehicleMotion{}, FusionParams{}), romo::Error);
  RigCloud nan_rig{1, 0, Eigen::Isometry3f::Identity(), {}};
  nan_rig.cloud.PushBack(Eigen::Vector3f(std::nanf(""), 0, 0));
  FusionStats stats;
  EXPECT_EQ(FuseRigClouds({nan_rig}, VehicleMotion{}, FusionParams{}, &stats).size(), 0u);
  EXPECT_EQ(stats.skipped_non_finite, 1u);
  EXPECT_EQ(FuseRigClouds({}, VehicleMotion{}, FusionParams{}).size(), 0u);
}

}  // namespace
}  // namespace romo::mapping
