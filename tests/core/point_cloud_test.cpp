#include "romo/core/point_cloud.hpp"

#include <gtest/gtest.h>

#include "romo/core/check.hpp"

namespace romo {
namespace {

TEST(PointCloudTest, AppendSelectAndTransformKeepChannelsAligned) {
  PointCloud a;
  a.PushBack({1.f, 2.f, 3.f}, 0.1f, 10.f);
  a.PushBack({4.f, 5.f, 6.f}, 0.2f, 20.f);
  PointCloud b;
  b.PushBack({7.f, 8.f, 9.f}, 0.3f, 30.f);
  a.Append(b);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_TRUE(a.IsConsistent());

  const PointCloud picked = a.Select({2, 0});
  ASSERT_EQ(picked.size(), 2u);
  EXPECT_FLOAT_EQ(picked.xyz(0, 0), 7.f);
  EXPECT_FLOAT_EQ(picked.sigma_z_m[0], 0.3f);
  EXPECT_FLOAT_EQ(picked.intensity[1], 10.f);

  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::AngleAxisf(static_cast<float>(M_PI / 2), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3f(1.f, 0.f, 0.f);
  PointCloud moved = picked;
  moved.Transform(T);
  // (7, 8, 9) rotated 90 deg about z is (-8, 7, 9), then shifted by +1 in x.
  EXPECT_NEAR(moved.xyz(0, 0), -7.f, 1e-5f);
  EXPECT_NEAR(moved.xyz(1, 0), 7.f, 1e-5f);
  EXPECT_NEAR(moved.xyz(2, 0), 9.f, 1e-5f);
}

TEST(PointCloudTest, SelectRejectsOutOfRangeIndex) {
  PointCloud a;
  a.PushBack({0.f, 0.f, 0.f});
  EXPECT_THROW(a.Select({1}), Error);
  EXPECT_THROW(a.Select({-1}), Error);
}

}  // namespace
}  // namespace romo
