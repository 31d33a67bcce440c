// Location areas (Sec. 3.3): stays of the projected hand path and the ends of transport paths,
// clustered; on a synthetic path with known answers and on simulated scenes with transports.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/indoor_manip/location_areas.hpp"
#include "romo/sim_manip/manip_eval.hpp"

namespace romo::indoor_manip {
namespace {

// Path in the plane: works (small circles) at A, carried 0.3 m to B, works, carried back to A.
Fingerprint TwoSpotPath() {
  Fingerprint fp;
  const double fps = 30.0;
  const Eigen::Vector2d A(0.0, 0.0), B(0.3, 0.0);
  auto add = [&](const Eigen::Vector2d& p) {
    fp.profiles.t_s.push_back(fp.profiles.size() / fps);
    fp.profiles.x_m.push_back(p.x());
    fp.profiles.y_m.push_back(p.y());
    fp.profiles.r_m.push_back(0.05);
  };
  auto work = [&](const Eigen::Vector2d& c) {
    for (int k = 0; k < 60; ++k) add(c + 0.02 * Eigen::Vector2d(std::cos(k * 0.5), std::sin(k * 0.5)));
  };
  auto carry = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    for (int k = 1; k <= 30; ++k) add(a + (b - a) * (k / 31.0));
  };
  work(A);
  carry(A, B);
  work(B);
  carry(B, A);
  work(A);
  return fp;
}

TEST(LocationAreasTest, TwoSpotsWithTransportsGiveTwoAreasAndTheirEnds) {
  const Fingerprint fp = TwoSpotPath();
  const LocationAnalysis loc = FindLocationAreas(fp, LocationParams{});
  ASSERT_EQ(loc.areas.size(), 2u);
  ASSERT_EQ(loc.transports.size(), 2u);
  // The circles are centred on the spots: the area centres are exact up to the anchor's
  // sampling of the circle (a few mm).
  constexpr double kCentreTolM = 0.005;
  EXPECT_LT(loc.areas[0].centre_xy_m.norm(), kCentreTolM);
  EXPECT_LT((loc.areas[1].centre_xy_m - Eigen::Vector2d(0.3, 0.0)).norm(), kCentreTolM);
  EXPECT_EQ(loc.areas[0].stays, 2);
  EXPECT_EQ(loc.areas[0].transport_starts, 1);
  EXPECT_EQ(loc.areas[0].transport_ends, 1);
  EXPECT_EQ(loc.areas[1].transport_starts, 1);
  EXPECT_EQ(loc.areas[1].transport_ends, 1);
  EXPECT_EQ(loc.transports[0].from_area, 0);
  EXPECT_EQ(loc.transports[0].to_area, 1);
  EXPECT_EQ(loc.transports[1].from_area, 1);
  EXPECT_EQ(loc.transports[1].to_area, 0);
  // The transport starts and stops near the spots: within the stays' cores (the 2 cm circles
  // plus the first approach steps, 1 cm apart): measured 2.9 and 3.9 cm.
  constexpr double kEndTolM = 0.05;
  EXPECT_LT(loc.transports[0].start_xy_m.norm(), kEndTolM);
  EXPECT_LT((loc.transports[0].end_xy_m - Eigen::Vector2d(0.3, 0.0)).norm(), kEndTolM);
  // Its length: the 30 cm between the spots less the two core ends above (measured 23 cm).
  EXPECT_NEAR(loc.transports[0].length_m, 0.3 - 0.029 - 0.039, 0.01);
  EXPECT_NEAR(loc.areas[0].radius_m, 0.02, 0.003);
}

TEST(LocationAreasTest, PathWithoutStaysIsOneWorkingArea) {
  Fingerprint fp;
  for (int k = 0; k < 120; ++k) {  // a 0.6 m row traversed back and forth at 0.6 m/s
    const double s = std::fmod(k / 60.0, 2.0);
    fp.profiles.t_s.push_back(k / 60.0);
    fp.profiles.x_m.push_back(0.6 * (s < 1.0 ? s : 2.0 - s) - 0.3);
    fp.profiles.y_m.push_back(0.0);
    fp.profiles.r_m.push_back(0.0);
  }
  const LocationAnalysis loc = FindLocationAreas(fp, LocationParams{});
  ASSERT_EQ(loc.areas.size(), 1u);
  EXPECT_EQ(loc.areas[0].sources, std::vector<std::string>{"path"});
  EXPECT_TRUE(loc.transports.empty());
  EXPECT_LT(loc.areas[0].centre_xy_m.norm(), 0.01);
  LocationParams bad;
  bad.stay_radius_m = -1;
  EXPECT_THROW(FindLocationAreas(fp, bad), romo::Error);
}

// The whole plugin on sim-manip scenes whose hand is carried between two spots 30 cm apart.
TEST(LocationAreasTest, SimulatedTransportsFoundAsAreasAtTheTrueSpots) {
  // The measured hand centroid is the centroid of the visible hand surface, a few cm from the
  // ellipsoid's centre (semi-axes 4.5/3.5/2.5 cm, seen at ~50 deg): projected onto the plane that
  // shifts an area by up to ~2.5 cm. 4 cm is that plus the Kalman smoothing of the path.
  constexpr double kAreaCentreTolM = 0.04;
  for (const char* action : {"tightening", "hitting", "pulling"}) {
    for (int seed : {100, 101}) {
      sim_manip::SimManipOptions o;
      o.action = action;
      o.seed = static_cast<std::uint64_t>(seed);
      o.frames = 240;
      o.transports = 2;
      const sim_manip::SimManipScene scene(o);
      const auto& truth = scene.truth().work_area_centres_camera_m;
      ASSERT_EQ(truth.size(), 2u);
      ManipParams params;
      params.object_map = false;  // locations only
      const ManipResult r = sim_manip::AnalyzeSimManip(o, params);
      const auto& loc = r.locations;
      std::printf("%s seed %d: %zu areas, %zu transports, %d stays\n", action, seed, loc.areas.size(),
                  loc.transports.size(), loc.stays);
      ASSERT_EQ(loc.areas.size(), 2u) << action << " " << seed;
      EXPECT_EQ(loc.transports.size(), 2u) << action << " " << seed;
      for (const auto& t : truth) {
        double best = 1e9;
        for (const auto& a : loc.areas) best = std::min(best, (a.centre_camera_m - t).norm());
        std::printf("  area error %.4f m\n", best);
        EXPECT_LT(best, kAreaCentreTolM) << action << " " << seed;
      }
      for (const auto& a : loc.areas) {
        EXPECT_GE(a.transport_starts + a.transport_ends, 1) << action << " " << seed;
      }
    }
  }
}

}  // namespace
}  // namespace romo::indoor_manip
