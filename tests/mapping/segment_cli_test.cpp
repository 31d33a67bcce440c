#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "romo/mapping/synthetic_scene.hpp"
#include "romo/stereo/pcd_io.hpp"
#include "test_support.hpp"

namespace romo::mapping {
namespace {

test::CommandResult Romo(const std::string& args) { return test::RunRomo(args); }

int Count(const std::string& s, const std::string& what) {
  int n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

TEST(SegmentCliTest, JsonReportsGroundPlaneAndOneBlobPerObject) {
  test::ScratchDir dir;
  SyntheticSceneParams sp;
  sp.density_per_m2 = 300.f;
  sp.ground_half_extent_m = 12.f;
  sp.noise_m = 0.01f;
  SceneObject car;
  car.center_xy = {6.f, 3.f};
  car.size = {4.5f, 1.8f, 1.5f};
  car.yaw_rad = 0.2f;
  SceneObject ped;
  ped.shape = SceneObject::Shape::kCylinder;
  ped.center_xy = {4.f, -3.f};
  ped.size = {0.5f, 0.5f, 1.75f};
  SceneObject pole = ped;
  pole.center_xy = {-5.f, 2.f};
  pole.size = {0.2f, 0.2f, 3.f};
  const SyntheticScene scene = MakeSyntheticScene({car, ped, pole}, sp);
  stereo::SavePcd(scene.cloud, dir / "scene.pcd");

  const auto r = Romo("segment --pcd " + dir / "scene.pcd" + " --json --out " + dir / "out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"points\": " + std::to_string(scene.cloud.size())), std::string::npos) << r.out;
  float a = 0, b = 0, c = 0, d = 0;
  const auto plane_at = r.out.find("\"plane\": [");
  ASSERT_NE(plane_at, std::string::npos);
  ASSERT_EQ(std::sscanf(r.out.c_str() + plane_at, "\"plane\": [%f, %f, %f, %f]", &a, &b, &c, &d), 4);
  constexpr float kPlaneTolerance = 0.01f;  // 1 cm noise on a 24 m ground patch
  EXPECT_NEAR(c, 1.f, kPlaneTolerance);
  EXPECT_NEAR(d, 0.f, kPlaneTolerance);
  EXPECT_NEAR(a * a + b * b + c * c, 1.f, 1e-4f);  // unit normal
  EXPECT_EQ(Count(r.out, "\"class\""), 3) << r.out;
  EXPECT_TRUE(std::ifstream(dir / "out/topview.png").good());
  EXPECT_TRUE(std::ifstream(dir / "out/blob_002.pcd").good());
  EXPECT_EQ(stereo::LoadPcd(dir / "out/blob_000.pcd").size() > 100, true);
}

TEST(SegmentCliTest, BadInputExitsWithAClearError) {
  test::ScratchDir dir;
  const auto missing = Romo("segment --pcd " + dir / "nope.pcd");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("nope.pcd"), std::string::npos) << missing.err;
  PointCloud one;
  one.PushBack(Eigen::Vector3f(1, 2, 3));
  stereo::SavePcd(one, dir / "one.pcd");
  const auto leaf = Romo("segment --pcd " + dir / "one.pcd" + " --leaf 0");
  EXPECT_EQ(leaf.exit_code, 2);
  EXPECT_NE(leaf.err.find("leaf_size_m"), std::string::npos) << leaf.err;
  const auto single = Romo("segment --pcd " + dir / "one.pcd" + " --json --min-points 1");
  ASSERT_EQ(single.exit_code, 0) << single.err;
  EXPECT_NE(single.out.find("\"points\": 1,"), std::string::npos) << single.out;
}

}  // namespace
}  // namespace romo::mapping
