// The parking scene's layout and scripts: sizes from the issue, bays that fit (or not), a
// collision-free world, the three-stage maneuver and the Fig. 4.16 occlusions.
#include "romo/sim/scene.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace romo::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFrameDtS = 0.1;             // 10 Hz
constexpr double kScriptEndS = 30.0;          // pedestrians have reached their goals by then
constexpr double kAngleTolRad = 1e-9;         // analytic poses: only rounding error
constexpr double kPositionTolM = 1e-9;
const std::uint64_t kSeeds[] = {1, 2, 3, 17, 12345};
// A bay is bounded by its neighbours, so it touches them; shrink it by this before testing.
constexpr double kTouchTolM = 1e-6;

TEST(ParkingSceneTest, CarsHaveRealisticSizes) {
  for (std::uint64_t seed : kSeeds) {
    const ParkingScene scene(ParkingSceneParams{seed});
    int cars = 0;
    for (const GtBox& b : scene.ObjectsAt(0.0)) {
      if (b.class_name != "car") continue;
      ++cars;
      EXPECT_GE(b.size_m.x(), 4.0);
      EXPECT_LE(b.size_m.x(), 5.0);
      EXPECT_GE(b.size_m.y(), 1.7);
      EXPECT_LE(b.size_m.y(), 1.9);
      EXPECT_GE(b.size_m.z(), 1.4);
      EXPECT_LE(b.size_m.z(), 1.6);
      EXPECT_NEAR(b.center_m.z(), b.size_m.z() / 2, kPositionTolM);  // standing on the ground
    }
    EXPECT_GE(cars, 6) << "seed " << seed;
  }
}

TEST(ParkingSceneTest, HasOneFeasibleAndOneTooNarrowBayThatTouchNoCar) {
  for (std::uint64_t seed : kSeeds) {
    const ParkingScene scene(ParkingSceneParams{seed});
    const auto boxes = scene.ObjectsAt(0.0);
    const double ego_length = scene.params().ego_size_m.x();
    int feasible = 0, narrow = 0;
    for (const GtBay& bay : scene.bays()) {
      if (bay.feasible) {
        ++feasible;
        // RoMo enters sideways: its 2.8 m length plus 0.2 m on each side.
        EXPECT_GE(bay.width_m, ego_length + 0.4);
      } else {
        EXPECT_LT(bay.width_m, 2.2);
        ++narrow;
      }
      GtBay inner = bay;
      inner.width_m -= 2 * kTouchTolM;
      inner.depth_m -= 2 * kTouchTolM;
      for (const GtBox& b : boxes) {
        if (b.class_name != "car") continue;
        EXPECT_FALSE(FootprintsOverlap(inner.AsBox(2.0), b))
            << "seed " << seed << ": bay " << bay.id << " overlaps car " << b.id;
      }
      // The neighbours named by the bay are the cars that bound it.
      const GtBox* left = nullptr;
      const GtBox* right = nullptr;
      for (const GtBox& b : boxes) {
        if (b.id == bay.left_car_id) left = &b;
        if (b.id == bay.right_car_id) right = &b;
      }
      ASSERT_NE(left, nullptr);
      ASSERT_NE(right, nullptr);
      EXPECT_LT(left->center_m.x(), bay.center_m.x());
      EXPECT_GT(right->center_m.x(), bay.center_m.x());
    }
    EXPECT_EQ(feasible, 1) << "seed " << seed;
    EXPECT_EQ(narrow, 1) << "seed " << seed;
  }
}

TEST(ParkingSceneTest, SameSeedSameSceneOtherSeedOtherScene) {
  const ParkingScene a(ParkingSceneParams{7}), b(ParkingSceneParams{7}), c(ParkingSceneParams{8});
  const auto ba = a.ObjectsAt(3.3), bb = b.ObjectsAt(3.3), bc = c.ObjectsAt(3.3);
  ASSERT_EQ(ba.size(), bb.size());
  bool differs = false;
  for (std::size_t i = 0; i < ba.size(); ++i) {
    EXPECT_EQ(ba[i].center_m, bb[i].center_m);
    EXPECT_EQ(ba[i].size_m, bb[i].size_m);
    if (i < bc.size() && ba[i].center_m != bc[i].center_m) differs = true;
  }
  EXPECT_TRUE(differs);
}

TEST(ParkingSceneTest, NothingCollidesWithCarsTheEgoOrEachOther) {
  for (std::uint64_t seed : kSeeds) {
    const ParkingScene scene(ParkingSceneParams{seed});
    for (double t = 0.0; t <= kScriptEndS; t += kFrameDtS) {
      const auto boxes = scene.ObjectsAt(t);
      GtBox ego;
      ego.size_m = scene.params().ego_size_m;
      const EgoState es = scene.EgoAt(t);
      ego.center_m = es.T_world_vehicle.translation();
      const Eigen::Vector3d x_axis = es.T_world_vehicle.linear().col(0);
      ego.yaw_rad = std::atan2(x_axis.y(), x_axis.x());
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        EXPECT_FALSE(FootprintsOverlap(ego, boxes[i]))
            << "seed " << seed << " t " << t << ": ego hits " << boxes[i].id;
        for (std::size_t j = i + 1; j < boxes.size(); ++j) {
          if (boxes[i].class_name != "pedestrian" && boxes[j].class_name != "pedestrian") continue;
          EXPECT_FALSE(FootprintsOverlap(boxes[i], boxes[j]))
              << "seed " << seed << " t " << t << ": " << boxes[i].id << " hits " << boxes[j].id;
        }
      }
    }
  }
}

TEST(ParkingSceneTest, EgoApproachesTurnsOnTheSpotAndEntersSideways) {
  const ParkingScene scene(ParkingSceneParams{1});
  const GtBay* target = nullptr;
  for (const GtBay& bay : scene.bays()) {
    if (bay.feasible) target = &bay;
  }
  ASSERT_NE(target, nullptr);
  auto yaw_of = [](const EgoState& s) {
    const Eigen::Vector3d x = s.T_world_vehicle.linear().col(0);
    return std::atan2(x.y(), x.x());
  };
  // Sample the maneuver and check each phase's motion.
  double turn_start_yaw = 0.0, turn_end_yaw = 0.0;
  Eigen::Vector3d turn_position = Eigen::Vector3d::Zero();
  bool saw_turn = false, saw_entry = false;
  EgoState prev = scene.EgoAt(0.0);
  for (double t = kFrameDtS; t <= scene.maneuver_duration_s() + 1.0; t += kFrameDtS) {
    const EgoState s = scene.EgoAt(t);
    const Eigen::Vector3d step = s.T_world_vehicle.translation() - prev.T_world_vehicle.translation();
    const Eigen::Vector3d heading = prev.T_world_vehicle.linear().col(0);
    if (s.phase == "approach" && prev.phase == "approach") {
      // Forward driving: motion along the heading only.
      EXPECT_NEAR(step.dot(heading), step.norm(), 1e-9);
    } else if (s.phase == "turn") {
      if (!saw_turn) {
        turn_start_yaw = yaw_of(prev);
        turn_position = prev.T_world_vehicle.translation();
      }
      saw_turn = true;
      EXPECT_LT((s.T_world_vehicle.translation() - turn_position).norm(), kPositionTolM);
      turn_end_yaw = yaw_of(s);
    } else if (s.phase == "entry" && prev.phase == "entry") {
      saw_entry = true;
      // Sideways: motion along the vehicle's y axis (its left), none along its heading.
      const Eigen::Vector3d left = prev.T_world_vehicle.linear().col(1);
      EXPECT_NEAR(step.dot(heading), 0.0, 1e-9);
      EXPECT_GT(step.dot(left), 0.0);
    }
    prev = s;
  }
  EXPECT_TRUE(saw_turn);
  EXPECT_TRUE(saw_entry);
  EXPECT_NEAR(std::abs(turn_end_yaw - turn_start_yaw), kPi / 2, 1e-3);  // a 90 degree turn
  // Parked inside the feasible bay.
  const EgoState parked = scene.EgoAt(scene.maneuver_duration_s() + 5.0);
  EXPECT_EQ(parked.phase, "parked");
  GtBox bay_box = target->AsBox(2.0);
  EXPECT_TRUE(bay_box.Contains(parked.T_world_vehicle.translation() + Eigen::Vector3d(0, 0, 0.5)));
  EXPECT_NEAR(parked.speed_mps, 0.0, 1e-12);
  // The approach spot is centred in front of the bay.
  EXPECT_NEAR(turn_position.x(), target->center_m.x(), kPositionTolM);
  EXPECT_LT(turn_position.y(), target->center_m.y() - target->depth_m / 2);
}

TEST(ParkingSceneTest, SpeedsMatchThePoses) {
  const ParkingScene scene(ParkingSceneParams{3});
  constexpr double kDt = 1e-4;          // s, central differences
  constexpr double kRateTol = 1e-3;     // m/s and rad/s: second-order difference error
  for (double t = 0.05; t < scene.maneuver_duration_s(); t += 0.37) {
    const EgoState a = scene.EgoAt(t - kDt), b = scene.EgoAt(t + kDt), s = scene.EgoAt(t);
    if (a.phase != b.phase) continue;
    const double speed =
        (b.T_world_vehicle.translation() - a.T_world_vehicle.translation()).norm() / (2 * kDt);
    EXPECT_NEAR(s.speed_mps, speed, kRateTol) << "t " << t;
    const Eigen::Vector3d xa = a.T_world_vehicle.linear().col(0), xb = b.T_world_vehicle.linear().col(0);
    const double yaw_rate = std::atan2(xa.x() * xb.y() - xa.y() * xb.x(), xa.dot(xb)) / (2 * kDt);
    EXPECT_NEAR(s.yaw_rate_radps, yaw_rate, kRateTol) << "t " << t;
  }
  for (const auto& p : scene.pedestrians()) {
    for (double t = 0.05; t < kScriptEndS; t += 0.41) {
      const PedestrianState s = EvaluatePedestrian(p, t);
      const Eigen::Vector2d v =
          (EvaluatePedestrian(p, t + kDt).position_m - EvaluatePedestrian(p, t - kDt).position_m) /
          (2 * kDt);
      // Skip instants next to a start or stop (the velocity jumps there).
      if ((EvaluatePedestrian(p, t + kDt).velocity_mps - EvaluatePedestrian(p, t - kDt).velocity_mps)
              .norm() > 1e-9) {
        continue;
      }
      EXPECT_NEAR((s.velocity_mps - v).norm(), 0.0, kRateTol) << "ped " << p.id << " t " << t;
    }
  }
}

// Angular interval [lo, hi] (rad) a box's footprint covers seen from the ego's centre.
std::pair<double, double> Bearings(const GtBox& b, const Eigen::Vector2d& eye, double ref) {
  double lo = 1e9, hi = -1e9;
  for (const auto& c : b.Footprint()) {
    double a = std::atan2(c.y() - eye.y(), c.x() - eye.x()) - ref;
    a = std::atan2(std::sin(a), std::cos(a));
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  return {lo, hi};
}

TEST(ParkingSceneTest, PedestriansOccludeEachOtherTotallyAndPartly) {
  // Fig. 4.16c: a pedestrian hidden completely by a nearer one for several frames, and two
  // whose silhouettes overlap partly (blobs that merge), seen from the ego vehicle.
  constexpr int kMinFrames = 5;  // 0.5 s at 10 Hz: "for a while"
  for (std::uint64_t seed : kSeeds) {
    const ParkingScene scene(ParkingSceneParams{seed});
    auto count = [&](std::pair<int, int> ids, bool total) {
      int frames = 0;
      for (double t = 0.0; t <= kScriptEndS; t += kFrameDtS) {
        const auto boxes = scene.ObjectsAt(t);
        const GtBox *a = nullptr, *b = nullptr;
        for (const auto& box : boxes) {
          if (box.id == ids.first) a = &box;
          if (box.id == ids.second) b = &box;
        }
        const Eigen::Vector2d eye = scene.EgoAt(t).T_world_vehicle.translation().head<2>();
        const Eigen::Vector2d to_a = a->center_m.head<2>() - eye, to_b = b->center_m.head<2>() - eye;
        const bool a_nearer = to_a.norm() < to_b.norm();
        const GtBox& near = a_nearer ? *a : *b;
        const GtBox& far = a_nearer ? *b : *a;
        const Eigen::Vector2d dir = far.center_m.head<2>() - eye;
        const double ref = std::atan2(dir.y(), dir.x());
        const auto n = Bearings(near, eye, ref), f = Bearings(far, eye, ref);
        const bool overlap = n.first < f.second && f.first < n.second;
        const bool covered = n.first <= f.first && n.second >= f.second;
        if (total ? covered : (overlap && !covered)) ++frames;
      }
      return frames;
    };
    EXPECT_GE(count(scene.total_occlusion_pair(), true), kMinFrames) << "seed " << seed;
    EXPECT_GE(count(scene.partial_occlusion_pair(), false), kMinFrames) << "seed " << seed;
  }
}

TEST(ParkingSceneTest, PedestriansWalkStopAndTurn) {
  const ParkingScene scene(ParkingSceneParams{5});
  for (const auto& p : scene.pedestrians()) {
    EXPECT_GE(p.size_m.z(), 1.6);
    EXPECT_LE(p.size_m.z(), 1.9);
    int stopped = 0, walking = 0;
    double min_heading = 1e9, max_heading = -1e9;
    for (double t = p.start_s + 0.05; t < kScriptEndS; t += kFrameDtS) {
      const PedestrianState s = EvaluatePedestrian(p, t);
      if (s.velocity_mps.norm() > 0.5) {
        ++walking;
        min_heading = std::min(min_heading, s.heading_rad);
        max_heading = std::max(max_heading, s.heading_rad);
      } else {
        ++stopped;
      }
    }
    EXPECT_GT(walking, 20) << p.id;
    EXPECT_GT(stopped, 5) << p.id;
    EXPECT_GT(max_heading - min_heading, 0.3) << p.id << " never turns";
  }
}

}  // namespace
}  // namespace romo::sim
