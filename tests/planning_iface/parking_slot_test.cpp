// Parking-slot estimation on synthetic car boxes with known answers.
#include "romo/planning_iface/parking_slot.hpp"

#include <cmath>
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"

namespace romo::planning_iface {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Pure geometry on exact inputs: only floating-point rounding separates result and answer.
constexpr double kExactM = 1e-9;
constexpr double kExactRad = 1e-9;

constexpr double kCarLength = 4.5;
constexpr double kCarWidth = 1.8;

GroundBox Car(int id, double x, double y, double yaw = 0.0) {
  GroundBox b;
  b.id = id;
  b.center_m = {x, y};
  b.yaw_rad = yaw;
  b.length_m = kCarLength;
  b.width_m = kCarWidth;
  return b;
}

// A parallel-parking row along x at y = row_y: car 0 ends at x = 0, the gap, then car 1.
std::vector<GroundBox> ParallelPair(double gap_m, double row_y = 5.0) {
  return {Car(0, -kCarLength / 2, row_y), Car(1, gap_m + kCarLength / 2, row_y)};
}

TEST(ParkingSlotTest, WideParallelGapHasKnownPoseApproachAndClearance) {
  const ParkingParams params;
  const double gap = 4.0;
  Pose2 ego;
  ego.position_m = {gap / 2, 0.0};
  const auto slots = FindParkingSlots(ParallelPair(gap), ego, params);
  ASSERT_EQ(slots.size(), 1u);
  const ParkingSlot& s = slots[0];
  EXPECT_TRUE(s.feasible) << s.reason;
  EXPECT_NEAR(s.target.position_m.x(), gap / 2, kExactM);
  EXPECT_NEAR(s.target.position_m.y(), 5.0, kExactM);
  EXPECT_NEAR(s.target.yaw_rad, 0.0, kExactRad);
  EXPECT_NEAR(s.length_m, gap, kExactM);
  EXPECT_NEAR(s.depth_m, kCarWidth, kExactM);
  EXPECT_EQ(s.prev_id, 0);
  EXPECT_EQ(s.next_id, 1);
  // Approach spot: centred in front of the gap on the ego's side, far enough from the row's front
  // edge to turn on the spot: y = 5 - (0.9 + half diagonal 1.61 + 0.3).
  const double half_diagonal = 0.5 * std::hypot(params.ego_length_m, params.ego_width_m);
  const double approach_y = 5.0 - (kCarWidth / 2 + half_diagonal + params.turn_clearance_m);
  EXPECT_NEAR(s.approach.position_m.x(), gap / 2, kExactM);
  EXPECT_NEAR(s.approach.position_m.y(), approach_y, kExactM);
  EXPECT_NEAR(s.rotation_rad, 0.0, kExactRad);
  // Centred: equal clearance (gap - ego length) / 2 to both neighbours.
  EXPECT_NEAR(s.clearance_prev_m, (gap - params.ego_length_m) / 2, kExactM);
  EXPECT_NEAR(s.clearance_next_m, (gap - params.ego_length_m) / 2, kExactM);
  // Entry path: straight from the approach spot to the centre.
  ASSERT_EQ(static_cast<int>(s.entry_path_m.size()), params.entry_path_points);
  EXPECT_NEAR((s.entry_path_m.front() - s.approach.position_m).norm(), 0.0, kExactM);
  EXPECT_NEAR((s.entry_path_m.back() - s.target.position_m).norm(), 0.0, kExactM);
}

TEST(ParkingSlotTest, EntryIsSidewaysAndRotationAlignsWithNeighbours) {
  const ParkingParams params;
  Pose2 ego;  // driving head-on towards the row, facing +y
  ego.position_m = {2.0, -4.0};
  ego.yaw_rad = kPi / 2;
  const auto slots = FindParkingSlots(ParallelPair(4.0), ego, params);
  ASSERT_EQ(slots.size(), 1u);
  const ParkingSlot& s = slots[0];
  // Neighbours lie along x: aligning takes a quarter turn either way.
  EXPECT_NEAR(std::abs(s.rotation_rad), kPi / 2, kExactRad);
  EXPECT_NEAR(std::abs(std::sin(s.target.yaw_rad)), 0.0, kExactRad);
  // The path runs along the ego's own y axis once aligned: sideways (crab) entry.
  const Eigen::Vector2d path = s.entry_path_m.back() - s.entry_path_m.front();
  const Eigen::Vector2d heading(std::cos(s.target.yaw_rad), std::sin(s.target.yaw_rad));
  EXPECT_NEAR(path.normalized().dot(heading), 0.0, kExactM);
}

TEST(ParkingSlotTest, NarrowGapIsNeverFeasible) {
  const ParkingParams params;
  // Needed: ego length 2.8 + 2 x 0.2 margin = 3.2 m. Everything shorter must be refused.
  for (double gap = 0.6; gap < 3.2 - 1e-6; gap += 0.1) {
    Pose2 ego;
    ego.position_m = {gap / 2, 0.0};
    const auto slots = FindParkingSlots(ParallelPair(gap), ego, params);
    ASSERT_EQ(slots.size(), 1u) << "gap " << gap;
    EXPECT_FALSE(slots[0].feasible) << "gap " << gap;
    EXPECT_NE(slots[0].reason.find("gap"), std::string::npos) << slots[0].reason;
  }
  Pose2 ego;
  EXPECT_TRUE(FindParkingSlots(ParallelPair(3.25), ego, params)[0].feasible);
}

TEST(ParkingSlotTest, CarInFrontOfTheGapBlocksTheEntry) {
  const ParkingParams params;
  auto cars = ParallelPair(4.0);
  cars.push_back(Car(2, 2.0, 2.5, 0.3));  // standing in the aisle where the approach spot is
  Pose2 ego;
  ego.position_m = {2.0, -3.0};
  const auto slots = FindParkingSlots(cars, ego, params);
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_FALSE(slots[0].feasible);
  EXPECT_NE(slots[0].reason.find("blocked"), std::string::npos) << slots[0].reason;
}

TEST(ParkingSlotTest, PerpendicularBaysUseTheRowAcrossTheCars) {
  const ParkingParams params;
  // Cars side by side (yaw 90 deg) along x, as in the simulator's scene; gaps 3.6 m (fits the
  // ego lengthwise along the row: needs 2.8 + 2 x 0.2) and 2.0 m (does not).
  const double h = kCarWidth / 2;
  std::vector<GroundBox> cars = {Car(0, 0.0, 6.0, kPi / 2), Car(1, 2 * h + 3.6, 6.0, -kPi / 2),
                                 Car(2, 4 * h + 3.6 + 2.0, 6.0, kPi / 2)};
  Pose2 ego;  // coming from the south, facing the row
  ego.position_m = {h + 1.8, -4.0};
  ego.yaw_rad = kPi / 2;
  auto slots = FindParkingSlots(cars, ego, params);
  ASSERT_EQ(slots.size(), 2u);
  std::sort(slots.begin(), slots.end(),
            [](const auto& a, const auto& b) { return a.target.position_m.x() < b.target.position_m.x(); });
  EXPECT_NEAR(slots[0].length_m, 3.6, kExactM);
  EXPECT_NEAR(slots[0].depth_m, kCarLength, kExactM);
  EXPECT_NEAR(slots[0].target.position_m.x(), h + 1.8, kExactM);
  EXPECT_NEAR(slots[0].target.position_m.y(), 6.0, kExactM);
  // Ends heading along the row (east or west), a quarter turn from facing the row.
  EXPECT_NEAR(std::abs(std::sin(slots[0].target.yaw_rad)), 0.0, kExactRad);
  EXPECT_NEAR(std::abs(slots[0].rotation_rad), kPi / 2, kExactRad);
  EXPECT_TRUE(slots[0].feasible) << slots[0].reason;
  EXPECT_NEAR(slots[0].clearance_prev_m, (3.6 - params.ego_length_m) / 2, kExactM);
  EXPECT_NEAR(slots[1].length_m, 2.0, kExactM);
  EXPECT_FALSE(slots[1].feasible);
}

TEST(ParkingSlotTest, CarsFacingEachOtherAcrossTheAisleAreNoBay) {
  const ParkingParams params;
  // Two parallel rows 7 m apart; each row has one 4 m gap. The aisle between the rows is no bay.
  std::vector<GroundBox> cars = ParallelPair(4.0, 5.0);
  for (auto c : ParallelPair(4.0, -2.0)) {
    c.id += 10;
    cars.push_back(c);
  }
  Pose2 ego;
  ego.position_m = {2.0, 1.5};
  const auto slots = FindParkingSlots(cars, ego, params);
  ASSERT_EQ(slots.size(), 2u);
  for (const auto& s : slots) {
    EXPECT_NEAR(std::abs(s.target.position_m.y() - 1.5), 3.5, kExactM);
    EXPECT_TRUE(s.feasible) << s.reason;
  }
}

TEST(ParkingSlotTest, FootprintDistanceKnownAnswers) {
  GroundBox a = Car(0, 0, 0), b = Car(1, kCarLength + 1.0, 0);
  EXPECT_NEAR(FootprintDistance(a, b), 1.0, kExactM);
  b.center_m = {0, kCarWidth + 0.5};
  EXPECT_NEAR(FootprintDistance(a, b), 0.5, kExactM);
  b.center_m = {1.0, 0.5};
  EXPECT_EQ(FootprintDistance(a, b), 0.0);
  // A unit square turned 45 deg whose corner points at a's end face from 0.3 m away.
  GroundBox d;
  d.length_m = d.width_m = 1.0;
  d.yaw_rad = kPi / 4;
  d.center_m = {kCarLength / 2 + 0.3 + std::sqrt(0.5), 0.0};
  EXPECT_NEAR(FootprintDistance(a, d), 0.3, kExactM);
}

TEST(ParkingSlotTest, InvalidInputsNameFieldAndValue) {
  ParkingParams params;
  params.ego_length_m = -1;
  try {
    params.Validate();
    FAIL() << "no error";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("ego_length_m"), std::string::npos);
  }
  auto cars = ParallelPair(4.0);
  cars[1].width_m = std::nan("");
  try {
    FindParkingSlots(cars, Pose2{}, ParkingParams{});
    FAIL() << "no error";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("car box 1"), std::string::npos) << e.what();
  }
}

TEST(ParkingSlotTest, EstimatorKeepsIdSmoothsNoiseAndReplansAsTheEgoMoves) {
  // Noisy boxes (seeded): the filtered centre beats a single measurement.
  constexpr double kNoiseM = 0.05;        // 5 cm box-centre noise per frame
  constexpr double kFilteredTolM = 0.04;  // the running mean must land well inside the noise
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, kNoiseM);
  ParkingSlotEstimator estimator;
  const double gap = 4.0;
  Pose2 ego;
  ego.position_m = {gap / 2, -8.0};
  ego.yaw_rad = kPi / 2;
  int id = -1;
  double last_confidence = 0.0;
  for (int frame = 0; frame < 20; ++frame) {
    auto cars = ParallelPair(gap);
    for (auto& c : cars) c.center_m += Eigen::Vector2d(noise(rng), noise(rng));
    ego.position_m.y() += 0.25;  // driving towards the row
    const auto slots = estimator.Update(cars, ego);
    ASSERT_EQ(slots.size(), 1u);
    if (id < 0) id = slots[0].slot_id;
    EXPECT_EQ(slots[0].slot_id, id);
    EXPECT_GE(slots[0].confidence, last_confidence);
    last_confidence = slots[0].confidence;
  }
  const ParkingSlot s = estimator.slots()[0];
  EXPECT_NEAR(s.target.position_m.x(), gap / 2, kFilteredTolM);
  EXPECT_NEAR(s.target.position_m.y(), 5.0, kFilteredTolM);
  EXPECT_GT(s.confidence, 0.99);
  EXPECT_TRUE(s.feasible) << s.reason;
  EXPECT_NEAR(std::abs(s.rotation_rad), kPi / 2, 0.05);
  // Rotated on the spot: nothing left to turn.
  ego.yaw_rad = 0.0;
  auto slots = estimator.Update(ParallelPair(gap), ego);
  EXPECT_NEAR(slots[0].rotation_rad, 0.0, 0.05);
  // Occluded: kept, confidence decays, then forgotten after max_missed_frames.
  const double before = slots[0].confidence;
  slots = estimator.Update({}, ego);
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_LT(slots[0].confidence, before);
  EXPECT_EQ(slots[0].slot_id, id);
  for (int k = 0; k < ParkingParams{}.max_missed_frames; ++k) slots = estimator.Update({}, ego);
  EXPECT_TRUE(slots.empty());
}

TEST(ParkingSlotTest, AGapMeasuredInOneFrameOnlyIsNeverFeasible) {
  // A row of three cars 0.9 m apart. In one frame stereo misses the middle one, which leaves a
  // 6.3 m "gap"; in the next ones only the first car is seen (the others lost too), so no
  // measurement contradicts the gap and nothing seen stands in it: it must not be trusted.
  const double pitch = kCarLength + 0.9;
  const std::vector<GroundBox> middle_missed = {Car(0, 0.0, 5.0), Car(2, 2 * pitch, 5.0)};
  const std::vector<GroundBox> first_only = {Car(0, 0.0, 5.0)};
  Pose2 ego;
  ego.position_m = {pitch, -3.0};
  ego.yaw_rad = 0.0;
  ParkingSlotEstimator estimator;
  auto slots = estimator.Update(middle_missed, ego);
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_FALSE(slots[0].feasible) << "one frame's gap";
  EXPECT_NE(slots[0].reason.find("measured in 1 frame"), std::string::npos) << slots[0].reason;
  for (int k = 0; k < 5; ++k) {
    slots = estimator.Update(first_only, ego);
    ASSERT_EQ(slots.size(), 1u) << "kept while unseen";
    EXPECT_FALSE(slots[0].feasible) << "frame " << k + 1;
  }
  ParkingParams trusting;
  trusting.min_seen_frames = 1;
  ParkingSlotEstimator before(trusting);
  before.Update(middle_missed, ego);
  EXPECT_TRUE(before.Update(first_only, ego)[0].feasible) << "the test's premise: the rule alone stops it";
  // Measured twice, the same gap is a slot.
  ParkingSlotEstimator confirmed;
  confirmed.Update(middle_missed, ego);
  slots = confirmed.Update(middle_missed, ego);
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_TRUE(slots[0].feasible) << slots[0].reason;
  ParkingParams bad;
  bad.min_seen_frames = 0;
  EXPECT_THROW(bad.Validate(), Error);
}

TEST(ParkingSlotTest, NeighboursAreSmoothedLikeTheGapTheyBound) {
  // A perpendicular bay 3.3 m wide (the ego needs 3.2 m): 0.25 m to either neighbour once parked.
  const double h = kCarWidth / 2, gap = 3.3;
  const auto row = [&](double next_shift) {
    return std::vector<GroundBox>{Car(0, -h, 6.0, kPi / 2), Car(1, gap + h + next_shift, 6.0, -kPi / 2)};
  };
  Pose2 ego;
  ego.position_m = {gap / 2, -4.0};
  ego.yaw_rad = kPi / 2;
  ParkingSlotEstimator estimator;
  for (int frame = 0; frame < 5; ++frame) estimator.Update(row(0.0), ego);
  // One frame's box of the right neighbour 0.15 m into the gap: the smoothed target moves by
  // 0.4 x 0.075 m, the neighbour by 0.4 x 0.15 m, and the plan keeps its clearance (against that
  // one frame's box it would be 3.15 - (1.62 + 1.4) = 0.13 m, below the 0.15 m required).
  const auto slots = estimator.Update(row(-0.15), ego);
  ASSERT_EQ(slots.size(), 1u);
  const double w = ParkingParams{}.smoothing;
  const double target_x = gap / 2 + w * (-0.075);
  EXPECT_NEAR(slots[0].target.position_m.x(), target_x, kExactM);
  EXPECT_NEAR(slots[0].next_box.center_m.x(), gap + h - w * 0.15, kExactM);
  EXPECT_NEAR(slots[0].clearance_prev_m, target_x - 1.4, kExactM);
  EXPECT_NEAR(slots[0].clearance_next_m, gap - w * 0.15 - (target_x + 1.4), kExactM);
  EXPECT_TRUE(slots[0].feasible) << slots[0].reason;
}

TEST(ParkingSlotTest, DepthEdgesSeenOnTheGroundOutweighTheNeighbours) {
  // The perpendicular bay of PerpendicularBaysUseTheRowAcrossTheCars: the cars give its depth as
  // 3.75..8.25 m; the ground shows the painted front line at 3.4 m and the kerb at 8.8 m.
  const double h = kCarWidth / 2;
  const std::vector<GroundBox> cars = {Car(0, 0.0, 6.0, kPi / 2), Car(1, 2 * h + 3.6, 6.0, -kPi / 2)};
  Pose2 ego;
  ego.position_m = {h + 1.8, -4.0};
  ego.yaw_rad = kPi / 2;
  constexpr double kLineY = 3.4, kKerbY = 8.8;
  // Edges along the depth axis (into the bay, +y here) are measured from the candidate's target.
  const auto on_ground = [&](ParkingSlot& slot) {
    SetDepthEdges(&slot, kLineY - slot.target.position_m.y(), kKerbY - slot.target.position_m.y());
    slot.front_from_ground = slot.rear_from_ground = true;
  };
  ParkingSlotEstimator estimator;
  auto slots = estimator.Update(cars, ego);  // first from the cars alone
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_NEAR(slots[0].target.position_m.y(), 6.0, kExactM);
  EXPECT_FALSE(slots[0].front_from_ground);
  // Seen on the ground: taken at once, not averaged with the cars' guess.
  slots = estimator.Update(cars, ego, on_ground);
  ASSERT_EQ(slots.size(), 1u);
  EXPECT_NEAR(slots[0].target.position_m.y(), (kLineY + kKerbY) / 2, kExactM);
  EXPECT_NEAR(slots[0].depth_m, kKerbY - kLineY, kExactM);
  EXPECT_NEAR(slots[0].target.position_m.x(), h + 1.8, kExactM);
  EXPECT_TRUE(slots[0].front_from_ground && slots[0].rear_from_ground);
  // The approach spot keeps its distance from the painted line now.
  const double half_diagonal = 0.5 * std::hypot(ParkingParams{}.ego_length_m, ParkingParams{}.ego_width_m);
  EXPECT_NEAR(slots[0].approach.position_m.y(), kLineY - half_diagonal - ParkingParams{}.turn_clearance_m, kExactM);
  // The lines hidden again (under the ego, say): the cars do not pull the edges back.
  for (int frame = 0; frame < 5; ++frame) slots = estimator.Update(cars, ego);
  EXPECT_NEAR(slots[0].target.position_m.y(), (kLineY + kKerbY) / 2, kExactM);
  EXPECT_NEAR(slots[0].depth_m, kKerbY - kLineY, kExactM);
  // Only the front seen, 0.1 m off: it is smoothed, the rear stays.
  const auto front_only = [&](ParkingSlot& slot) {
    SetDepthEdges(&slot, kLineY + 0.1 - slot.target.position_m.y(), slot.depth_m / 2);
    slot.front_from_ground = true;
  };
  slots = estimator.Update(cars, ego, front_only);
  const double w = ParkingParams{}.smoothing;
  EXPECT_NEAR(slots[0].target.position_m.y() - slots[0].depth_m / 2, kLineY + w * 0.1, kExactM);
  EXPECT_NEAR(slots[0].target.position_m.y() + slots[0].depth_m / 2, kKerbY, kExactM);
  EXPECT_THROW(SetDepthEdges(&slots[0], 1.0, 1.0), Error);
}

TEST(ManeuverStageTest, ForwardTurnSidewaysFromPoses) {
  ManeuverStageTracker tracker;
  std::int64_t t = 0;
  const std::int64_t dt = 100'000'000;  // 10 Hz
  Pose2 p;
  p.yaw_rad = kPi / 2;
  for (int k = 0; k < 5; ++k, t += dt) {
    p.position_m.y() += 0.1;  // 1 m/s forward along +y (heading +y)
    tracker.Update(t, p);
  }
  EXPECT_EQ(tracker.stage(), ManeuverStage::kApproach);
  for (int k = 0; k < 5; ++k, t += dt) {
    p.yaw_rad -= 0.05;  // 0.5 rad/s on the spot
    tracker.Update(t, p);
  }
  EXPECT_EQ(tracker.stage(), ManeuverStage::kTurn);
  for (int k = 0; k < 3; ++k, t += dt) tracker.Update(t, p);  // a pause keeps the stage
  EXPECT_EQ(tracker.stage(), ManeuverStage::kTurn);
  for (int k = 0; k < 5; ++k, t += dt) {
    const Eigen::Vector2d left(-std::sin(p.yaw_rad), std::cos(p.yaw_rad));
    p.position_m += 0.03 * left;  // crab to the left
    tracker.Update(t, p);
  }
  EXPECT_EQ(tracker.stage(), ManeuverStage::kSideways);
  EXPECT_STREQ(ToString(tracker.stage()), "sideways");
  // An old stamp changes nothing.
  EXPECT_EQ(tracker.Update(0, Pose2{}), ManeuverStage::kSideways);
}

}  // namespace
}  // namespace romo::planning_iface
