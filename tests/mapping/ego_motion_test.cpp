// Ego-motion RANSAC with Mahalanobis gating (eqs. 3.12-3.13) and independent object motion on
// synthetic matches with known transforms, noise, mismatches and a moved object.
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/mapping/ego_motion.hpp"

namespace romo::mapping {
namespace {

constexpr double kSigmaM = 0.005;  // 5 mm point noise, Kinect-like at ~1.5 m

Eigen::Isometry3d Motion(double yaw_rad, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

struct Scene {
  MatchedPoints3D m;
  std::vector<char> object_k, object_k1;
};

// 300 static matches, 60 mismatches, 40 matches on an object that moved by T_obj.
Scene MakeScene(const Eigen::Isometry3d& T_ego, const Eigen::Isometry3d& T_obj, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n(0.0, kSigmaM);
  std::vector<Eigen::Vector3d> a, b;
  Scene s;
  auto add = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q, bool obj) {
    a.push_back(p);
    b.push_back(q + Eigen::Vector3d(n(rng), n(rng), n(rng)));
    s.object_k.push_back(obj);
    s.object_k1.push_back(obj);
  };
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p(u(rng), 0.6 * u(rng), 2.0 + 0.8 * u(rng));
    add(p, T_ego * p, false);
  }
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d p(u(rng), 0.6 * u(rng), 2.0 + 0.8 * u(rng));
    add(p, Eigen::Vector3d(u(rng), 0.6 * u(rng), 2.0 + 0.8 * u(rng)), false);
  }
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d p = Eigen::Vector3d(0.3, 0.1, 1.8) + 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    add(p, T_ego * (T_obj * p), true);  // object moved in the old camera frame, then the camera
  }
  s.m.p1.resize(3, a.size());
  s.m.p2.resize(3, b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    s.m.p1.col(i) = a[i];
    s.m.p2.col(i) = b[i];
    s.m.cov1.push_back(Eigen::Matrix3d::Identity() * kSigmaM * kSigmaM);
    s.m.cov2.push_back(Eigen::Matrix3d::Identity() * kSigmaM * kSigmaM);
  }
  return s;
}

TEST(EgoMotionTest, RecoversCameraMotionDespiteMismatchesAndAMovedObject) {
  const Eigen::Isometry3d T_ego = Motion(0.12, {0.15, -0.02, 0.1});
  const Eigen::Isometry3d T_obj = Motion(0.5, {0.0, 0.0, 0.25});
  const Scene s = MakeScene(T_ego, T_obj, 11);
  const auto ego = EstimateRigidMotion(s.m, EgoMotionParams{});
  ASSERT_TRUE(ego.has_value());
  const Eigen::Isometry3d d = T_ego.inverse() * ego->T_2_1;
  // 300 inliers with 5 mm noise: the fit is good to a millimetre and a few hundredths of a degree.
  constexpr double kMaxTransErrM = 0.003;
  constexpr double kMaxRotErrRad = 0.002;
  EXPECT_LT(d.translation().norm(), kMaxTransErrM);
  EXPECT_LT(Eigen::AngleAxisd(d.linear()).angle(), kMaxRotErrRad);
  // The 95% gate keeps ~95% of the true inliers and rejects the moved object and mismatches.
  EXPECT_GT(ego->inliers.size(), 270u);
  EXPECT_LT(ego->inliers.size(), 310u);
  int object_outliers = 0;
  for (int i : ego->outliers) object_outliers += s.object_k[i];
  EXPECT_EQ(object_outliers, 40);

  const auto obj = EstimateIndependentMotion(s.m, *ego, s.object_k, s.object_k1, EgoMotionParams{});
  ASSERT_TRUE(obj.has_value());
  const Eigen::Isometry3d expected = T_ego * T_obj;  // object points: frame k -> frame k+1
  const Eigen::Isometry3d e = expected.inverse() * obj->T_2_1;
  // 40 points spread over 20 cm: a coarser but still centimetre-level estimate.
  constexpr double kMaxObjTransErrM = 0.02;
  constexpr double kMaxObjRotErrRad = 0.05;
  EXPECT_LT(e.translation().norm(), kMaxObjTransErrM);
  EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), kMaxObjRotErrRad);
}

TEST(EgoMotionTest, TooFewMatchesIsAnExpectedFailureAndBadInputThrows) {
  MatchedPoints3D m;
  m.p1 = Eigen::Matrix3Xd::Random(3, 4);
  m.p2 = m.p1;
  m.cov1.assign(4, Eigen::Matrix3d::Identity() * 1e-4);
  m.cov2 = m.cov1;
  EXPECT_FALSE(EstimateRigidMotion(m, EgoMotionParams{}).has_value());
  m.cov2.pop_back();
  EXPECT_THROW(EstimateRigidMotion(m, EgoMotionParams{}), romo::Error);
  EgoMotionParams bad;
  bad.chi2_gate = -1;
  EXPECT_THROW(bad.Validate(), romo::Error);
}

}  // namespace
}  // namespace romo::mapping
