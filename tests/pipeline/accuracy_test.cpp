// Accuracy of the whole stack on the simulated parking scene `romo run` uses by default (seed 1,
// 40 frames, half resolution): detection, boxes, tracks and the parking slot against the scene's
// ground truth, scored by `romo eval scene`.
//
// Where the targets are met (slot yaw within 3 degrees, the too-narrow bay never reported
// feasible) they are asserted as such. Where they are not yet met (car and pedestrian
// recall/precision >= 0.95, slot centre within 0.15 m; see README "Accuracy") the figures of
// today's main are asserted as floors, each a few sightings below the figure measured, so that a
// change that loses accuracy fails here instead of passing unnoticed. The run is deterministic
// for a build (fixed seed, rendering and matching independent of thread count); the margins
// cover compiler and library differences in floating point.
#include <gtest/gtest.h>

#include "romo/pipeline/scene_eval.hpp"
#include "test_support.hpp"

namespace romo::pipeline {
namespace {

TEST(AccuracyTest, DefaultParkingSceneMeetsItsTargetsOrTodaysFloors) {
  romo::test::ScratchDir dir;
  const auto run = romo::test::RunRomo("run --no-pictures --out " + dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const SceneEval e = EvaluateSceneLog(dir / "outputs.lcmlog");
  std::printf("FIGURE accuracy: car P %.3f R %.3f (%lld/%lld), pedestrian P %.3f R %.3f (%lld/%lld), box centre "
              "%.3f m, ID switches %lld, slot %lld/%lld centre %.3f m yaw %.2f deg, narrow feasible %lld\n",
              e.car.precision(), e.car.recall(), static_cast<long long>(e.car.matched_truths),
              static_cast<long long>(e.car.truths), e.pedestrian.precision(), e.pedestrian.recall(),
              static_cast<long long>(e.pedestrian.matched_truths), static_cast<long long>(e.pedestrian.truths),
              e.box_center_err_m_median, static_cast<long long>(e.id_switches),
              static_cast<long long>(e.slot_found_frames), static_cast<long long>(e.slot_visible_frames),
              e.slot_center_err_m, e.slot_yaw_err_deg, static_cast<long long>(e.narrow_reported_feasible));
  std::printf("FIGURE accuracy, objects the cameras can see (>= %.0f %% of their facing surface): car P %.3f R %.3f "
              "(%lld/%lld), pedestrian P %.3f R %.3f (%lld/%lld)\n",
              100 * SceneEvalParams{}.min_visible_fraction, e.car_visible.precision(), e.car_visible.recall(),
              static_cast<long long>(e.car_visible.matched_truths), static_cast<long long>(e.car_visible.truths),
              e.pedestrian_visible.precision(), e.pedestrian_visible.recall(),
              static_cast<long long>(e.pedestrian_visible.matched_truths),
              static_cast<long long>(e.pedestrian_visible.truths));
  ASSERT_EQ(e.frames, 40);
  ASSERT_TRUE(e.visibility_scored) << "romo run writes the calibration into its outputs log";

  // Targets met.
  EXPECT_LE(e.slot_yaw_err_deg, 3.0);
  EXPECT_EQ(e.narrow_reported_feasible, 0);
  // Floors (measured with lone faces read as such, hidden parked cars remembered, people in
  // tandem split, coasting fragments no longer cars and walls framed by nearer cars unclassified:
  // car P 0.924 R 0.565, pedestrian P 0.865 R 0.750, centre 0.226 m, slot 31/32 at 0.218 m).
  // About 5 sightings of 300 (cars) and 200 (pedestrians) of margin.
  EXPECT_GE(e.car.recall(), 0.55);
  EXPECT_GE(e.car.precision(), 0.89);
  EXPECT_GE(e.pedestrian.recall(), 0.72);
  EXPECT_GE(e.pedestrian.precision(), 0.84);
  EXPECT_LE(e.box_center_err_m_median, 0.24);
  EXPECT_GE(e.slot_found_frames, e.slot_visible_frames - 2);
  EXPECT_LE(e.slot_center_err_m, 0.24);
  // Hidden objects (about 40 car and 25 pedestrian sightings) are neither missed nor found there.
  EXPECT_LT(e.car_visible.truths, e.car.truths);
  EXPECT_GE(e.car_visible.recall(), e.car.recall());
  EXPECT_GE(e.car_visible.recall(), 0.61);
  EXPECT_GE(e.pedestrian_visible.recall(), 0.77);
}

}  // namespace
}  // namespace romo::pipeline
