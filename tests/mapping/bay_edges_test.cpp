// Bay depth edges on synthetic ground: asphalt, a painted front line and a kerb of known
// positions and grey values, seeded noise.
#include "romo/mapping/bay_edges.hpp"

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"

namespace romo::mapping {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The bay in its own frame: depth s from the aisle (s < 0) into the bay, across it t.
struct Ground {
  double line_from = -2.70, line_to = -2.58;  // paint, 0.12 m wide; the bay starts at line_to
  double surface_from = 2.72;                 // kerb or verge from here on
  float asphalt = 80.f, paint = 180.f, surface = 120.f;
  float noise = 12.f;          // uniform +-, of the grey values
  double density_per_m2 = 400;  // what stereo leaves of the ground 6-8 m away
};

// The strip the cars give: fronts 0.35 m behind the line, rear 0.6 m short of the kerb.
BayStrip CarsStrip(const Ground& g, const Eigen::Vector2d& center, double yaw) {
  BayStrip strip;
  strip.center_m = center;
  strip.depth_axis = {std::cos(yaw), std::sin(yaw)};
  strip.half_width_m = 1.4;
  strip.front_m = g.line_to + 0.35;
  strip.rear_m = g.surface_from - 0.6;
  return strip;
}

// Ground points over the strip and around it, mapped into a cloud frame by T_cloud_frame.
PointCloud MakeGround(const Ground& g, const BayStrip& strip, const Eigen::Isometry3d& T_cloud_frame,
                      std::vector<int>* ground, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> s_dist(strip.front_m - 2.0, strip.rear_m + 2.0);
  std::uniform_real_distribution<double> t_dist(-2.5, 2.5);
  std::uniform_real_distribution<float> grey_noise(-g.noise, g.noise);
  const Eigen::Vector2d lateral(-strip.depth_axis.y(), strip.depth_axis.x());
  const double area = (strip.rear_m - strip.front_m + 4.0) * 5.0;
  const int n = static_cast<int>(area * g.density_per_m2);
  PointCloud cloud;  // filled in place: PushBack per point is quadratic under ASan
  cloud.Resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double s = s_dist(rng), t = t_dist(rng);
    float grey = g.asphalt;
    if (s >= g.line_from && s <= g.line_to) grey = g.paint;
    if (s >= g.surface_from) grey = g.surface;
    const Eigen::Vector2d xy = strip.center_m + s * strip.depth_axis + t * lateral;
    cloud.xyz.col(k) = (T_cloud_frame * Eigen::Vector3d(xy.x(), xy.y(), 0.0)).cast<float>();
    cloud.intensity[static_cast<std::size_t>(k)] = grey + grey_noise(rng);
    ground->push_back(k);
  }
  return cloud;
}

// The vehicle 9 m in front of a bay turned 30 degrees: the cloud is in the vehicle's frame.
Eigen::Isometry3d VehicleInWorld() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(-3.0, -7.0, 0.0);
  return T;
}

TEST(BayEdgesTest, FindsThePaintedFrontLineAndTheKerbBeyondTheCars) {
  const Ground g;
  const BayStrip strip = CarsStrip(g, {1.0, 2.0}, kPi / 6);
  const Eigen::Isometry3d T_world_vehicle = VehicleInWorld();
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(g, strip, T_world_vehicle.inverse(), &ground);
  const BayEdges e = FindBayEdges(cloud, ground, T_world_vehicle, strip, BayEdgeParams{});
  ASSERT_TRUE(e.front_m.has_value());
  ASSERT_TRUE(e.rear_m.has_value());
  // 400 points per m2 over a 2.2 m wide strip: about 9 points per cm of depth, so the 10th and
  // 90th percentiles of the edge points sit within about 2 cm of the true edge.
  constexpr double kEdgeToleranceM = 0.03;
  EXPECT_NEAR(*e.front_m, g.line_to, kEdgeToleranceM);
  EXPECT_NEAR(*e.rear_m, g.surface_from, kEdgeToleranceM);
  EXPECT_NEAR(e.reference_intensity, g.asphalt, 1.0);  // median of uniform noise about 80
  EXPECT_GT(e.reference_points, 1000);
}

TEST(BayEdgesTest, ADarkerVergeEndsTheBayToo) {
  Ground g;
  g.surface = 55.f;  // grass: darker than asphalt by more than surface_contrast
  const BayStrip strip = CarsStrip(g, {0.0, 6.0}, kPi / 2);
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(g, strip, Eigen::Isometry3d::Identity(), &ground);
  const BayEdges e = FindBayEdges(cloud, ground, Eigen::Isometry3d::Identity(), strip, BayEdgeParams{});
  ASSERT_TRUE(e.rear_m.has_value());
  EXPECT_NEAR(*e.rear_m, g.surface_from, 0.03);
}

TEST(BayEdgesTest, PlainAsphaltOrAWidePaintedAreaLeavesTheEdgesToTheCars) {
  Ground plain;
  plain.paint = plain.surface = plain.asphalt;
  const BayStrip strip = CarsStrip(plain, {0.0, 6.0}, kPi / 2);
  std::vector<int> ground;
  PointCloud cloud = MakeGround(plain, strip, Eigen::Isometry3d::Identity(), &ground);
  BayEdges e = FindBayEdges(cloud, ground, Eigen::Isometry3d::Identity(), strip, BayEdgeParams{});
  EXPECT_FALSE(e.front_m.has_value());
  EXPECT_FALSE(e.rear_m.has_value());

  // A painted crossing 0.8 m wide in front of the bay is no front line (max_paint_width_m 0.4).
  Ground crossing;
  crossing.line_from = crossing.line_to - 0.8;
  ground.clear();
  cloud = MakeGround(crossing, strip, Eigen::Isometry3d::Identity(), &ground);
  e = FindBayEdges(cloud, ground, Eigen::Isometry3d::Identity(), strip, BayEdgeParams{});
  EXPECT_FALSE(e.front_m.has_value());
  ASSERT_TRUE(e.rear_m.has_value());
  EXPECT_NEAR(*e.rear_m, crossing.surface_from, 0.03);
}

TEST(BayEdgesTest, TooLittleGroundSeenFindsNothing) {
  Ground sparse;
  sparse.density_per_m2 = 1.5;  // about 15 points over the bay's asphalt, below 30
  const BayStrip strip = CarsStrip(sparse, {0.0, 6.0}, kPi / 2);
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(sparse, strip, Eigen::Isometry3d::Identity(), &ground);
  const BayEdges e = FindBayEdges(cloud, ground, Eigen::Isometry3d::Identity(), strip, BayEdgeParams{});
  EXPECT_LT(e.reference_points, BayEdgeParams{}.min_reference_points);
  EXPECT_FALSE(e.front_m.has_value());
  EXPECT_FALSE(e.rear_m.has_value());
}

TEST(BayEdgesTest, BadInputNamesWhatIsWrong) {
  const Ground g;
  BayStrip strip = CarsStrip(g, {0.0, 6.0}, kPi / 2);
  std::vector<int> ground;
  const PointCloud cloud = MakeGround(g, strip, Eigen::Isometry3d::Identity(), &ground);
  const auto message = [&](const BayStrip& st, const BayEdgeParams& p, const std::vector<int>& idx) {
    try {
      FindBayEdges(cloud, idx, Eigen::Isometry3d::Identity(), st, p);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  BayEdgeParams params;
  params.paint_contrast = 0.9;
  EXPECT_NE(message(strip, params, ground).find("BayEdgeParams.paint_contrast = 0.9"), std::string::npos);
  params = {};
  params.bin_m = std::nan("");
  EXPECT_NE(message(strip, params, ground).find("BayEdgeParams.bin_m"), std::string::npos);
  BayStrip bad = strip;
  bad.depth_axis = {0.0, 2.0};
  EXPECT_NE(message(bad, {}, ground).find("invalid strip"), std::string::npos);
  bad = strip;
  bad.rear_m = bad.front_m;
  EXPECT_NE(message(bad, {}, ground).find("invalid strip"), std::string::npos);
  std::vector<int> outside = {0, static_cast<int>(cloud.size())};
  EXPECT_NE(message(strip, {}, outside).find("ground index " + std::to_string(cloud.size())), std::string::npos);
}

}  // namespace
}  // namespace romo::mapping
