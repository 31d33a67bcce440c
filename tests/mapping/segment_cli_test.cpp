#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

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

// Both scenes: a 24 m ground patch at 300 points/m^2 with 1 cm noise, and this car on it.
SyntheticSceneParams PatchParams() {
  SyntheticSceneParams sp;
  sp.density_per_m2 = 300.f;
  sp.ground_half_extent_m = 12.f;
  sp.noise_m = 0.01f;
  return sp;
}

SceneObject Car() {
  SceneObject car;
  car.center_xy = {6.f, 3.f};
  car.size = {4.5f, 1.8f, 1.5f};
  car.yaw_rad = 0.2f;
  return car;
}

TEST(SegmentCliTest, JsonReportsGroundPlaneAndOneBlobPerObject) {
  test::ScratchDir dir;
  const SyntheticSceneParams sp = PatchParams();
  const SceneObject car = Car();
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

TEST(SegmentCliTest, JsonBoxesAndAtlasClassesOfACarAndAPedestrian) {
  // A car and a pedestrian-sized box on a 24 m ground patch, 300 points/m^2, 1 cm noise.
  test::ScratchDir dir;
  SyntheticSceneParams sp = PatchParams();
  sp.seed = 21;
  const SceneObject car = Car();
  SceneObject ped;
  ped.center_xy = {4.f, -3.f};
  ped.size = {0.6f, 0.4f, 1.7f};
  ped.yaw_rad = -0.5f;
  const std::vector<SceneObject> objects = {car, ped};
  const SyntheticScene scene = MakeSyntheticScene(objects, sp);
  stereo::SavePcd(scene.cloud, dir / "scene.pcd");
  const PointCloud saved = stereo::LoadPcd(dir / "scene.pcd");  // what the tool reads
  ASSERT_EQ(saved.size(), scene.cloud.size());

  const auto r = Romo("segment --pcd " + dir / "scene.pcd" + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node js = YAML::Load(r.out);  // JSON is YAML
  EXPECT_EQ(js["points"].as<std::size_t>(), scene.cloud.size());

  // Ground: unit normal within 1 mrad of z (1 cm of height over 10 m; 170k inliers with 1 cm
  // noise over 24 m pin a refitted plane far closer, 0.08 mrad measured), through z = 0 within
  // 1 cm (the noise).
  constexpr double kUnitNormalTolerance = 1e-4;
  constexpr double kMaxGroundTiltRad = 0.001;
  constexpr double kMaxGroundOffsetM = 0.01;
  const YAML::Node plane = js["ground"]["plane"];
  ASSERT_EQ(plane.size(), 4u) << r.out;
  const Eigen::Vector3d n(plane[0].as<double>(), plane[1].as<double>(), plane[2].as<double>());
  const double d = plane[3].as<double>();
  EXPECT_NEAR(n.norm(), 1.0, kUnitNormalTolerance);
  EXPECT_LT(std::acos(std::min(1.0, n.z() / n.norm())), kMaxGroundTiltRad) << n.transpose();
  EXPECT_NEAR(d, 0.0, kMaxGroundOffsetM);

  const YAML::Node blobs = js["blobs"];
  ASSERT_EQ(blobs.size(), objects.size()) << r.out;
  // A blob is its object's points above the reported plane plus the 0.1 m ground tolerance;
  // points within 1 mm of that cut may fall either way (the plane is printed to 6 digits).
  constexpr double kGroundToleranceM = 0.1, kCutSlackM = 0.001;
  // The exact hull of points with 1 cm noise: a face's extreme point of its 300-2000 samples lies
  // 3-3.5 sigma out (up to 4.5 sigma in 1 of 100 faces), so an extent grows by up to 9 cm (two
  // faces; measured +3 to +7 cm); at 300 points/m^2 (6 cm spacing) a corner may be sampled up to
  // 3 cm inside. Centres within 4 cm (half the difference of the two ends' errors). Heading from
  // hull edges: the car's 4.5 m side with ends 9 cm apart across gives 0.02 rad, the
  // pedestrian's 0.6 m side 0.15 rad.
  constexpr float kMaxExtentGrowthM = 0.09f, kMaxExtentShrinkM = 0.03f, kCentreToleranceM = 0.04f;
  constexpr float kCarYawToleranceRad = 0.03f, kPedestrianYawToleranceRad = 0.15f;
  const char* const kClasses[] = {"car", "pedestrian"};
  const float kYawTolerances[] = {kCarYawToleranceRad, kPedestrianYawToleranceRad};
  std::vector<bool> matched(objects.size(), false);
  for (std::size_t o = 0; o < objects.size(); ++o) {
    const SceneObject& obj = objects[o];
    // The blob whose centre is nearest this object's.
    std::size_t best = 0;
    float best_dist = 1e9f;
    for (std::size_t b = 0; b < blobs.size(); ++b) {
      const Eigen::Vector2f c(blobs[b]["center"][0].as<float>(), blobs[b]["center"][1].as<float>());
      if ((c - obj.center_xy).norm() < best_dist) {
        best_dist = (c - obj.center_xy).norm();
        best = b;
      }
    }
    ASSERT_FALSE(matched[best]) << "two objects in one blob: " << r.out;
    matched[best] = true;
    const YAML::Node blob = blobs[best];
    std::size_t sure = 0, maybe = 0;
    for (std::size_t i = 0; i < saved.size(); ++i) {
      if (scene.labels[i] != static_cast<int>(o)) continue;
      const double h = n.dot(saved.xyz.col(static_cast<Eigen::Index>(i)).cast<double>()) + d;
      sure += h > kGroundToleranceM + kCutSlackM;
      maybe += h > kGroundToleranceM - kCutSlackM;
    }
    const auto points = blob["points"].as<std::size_t>();
    EXPECT_GE(points, sure) << kClasses[o];
    EXPECT_LE(points, maybe) << kClasses[o];
    // The blob is what is left above the cut, its box stood back on the ground (--ground-contact
    // 0.25 m: the cut is 0.1 m): from the plane up to the top.
    const float height = obj.size.z();
    const Eigen::Vector3f centre(obj.center_xy.x(), obj.center_xy.y(), 0.5f * height);
    const Eigen::Vector3f got_centre(blob["center"][0].as<float>(), blob["center"][1].as<float>(),
                                     blob["center"][2].as<float>());
    EXPECT_LT((got_centre - centre).norm(), kCentreToleranceM) << kClasses[o] << " " << got_centre.transpose();
    const Eigen::Vector3f size(obj.size.x(), obj.size.y(), height);
    for (int k = 0; k < 3; ++k) {
      const float got = blob["size"][k].as<float>();
      EXPECT_LE(got, size[k] + kMaxExtentGrowthM) << kClasses[o] << " extent " << k;
      EXPECT_GE(got, size[k] - kMaxExtentShrinkM) << kClasses[o] << " extent " << k;
    }
    // Unhinted yaw of a box: the length direction in [-pi/2, pi/2), i.e. modulo a half turn.
    const float yaw = blob["yaw"].as<float>();
    EXPECT_LT(std::abs(std::remainder(yaw - obj.yaw_rad, 3.14159265f)), kYawTolerances[o]) << kClasses[o] << " " << yaw;
    EXPECT_EQ(blob["class"].as<std::string>(), kClasses[o]);
  }

  // --ground-contact 0: the boxes as measured, from the cut up.
  const auto measured = Romo("segment --pcd " + dir / "scene.pcd" + " --json --ground-contact 0");
  ASSERT_EQ(measured.exit_code, 0) << measured.err;
  const YAML::Node measured_blobs = YAML::Load(measured.out)["blobs"];
  ASSERT_EQ(measured_blobs.size(), objects.size());
  for (std::size_t b = 0; b < measured_blobs.size(); ++b) {
    const float cut_height = blobs[b]["size"][2].as<float>() - static_cast<float>(kGroundToleranceM);
    EXPECT_NEAR(measured_blobs[b]["size"][2].as<float>(), cut_height, kMaxExtentGrowthM) << measured.out;
    EXPECT_EQ(measured_blobs[b]["points"].as<std::size_t>(), blobs[b]["points"].as<std::size_t>());
  }

  // --atlas: a file that is not there is named.
  const auto bad = Romo("segment --pcd " + dir / "scene.pcd" + " --atlas " + dir / "no_atlas.yaml");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("no_atlas.yaml"), std::string::npos) << bad.err;
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
  const auto contact = Romo("segment --pcd " + dir / "one.pcd" + " --ground-contact -0.2");
  EXPECT_EQ(contact.exit_code, 2);
  EXPECT_NE(contact.err.find("--ground-contact"), std::string::npos) << contact.err;
  const auto single = Romo("segment --pcd " + dir / "one.pcd" + " --json --min-points 1");
  ASSERT_EQ(single.exit_code, 0) << single.err;
  EXPECT_NE(single.out.find("\"points\": 1,"), std::string::npos) << single.out;
}

}  // namespace
}  // namespace romo::mapping
