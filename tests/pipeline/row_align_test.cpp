// Cars parked side by side, seen obliquely 8-15 m away on the simulated parking scene: each frame
// alone through the pipeline, with and without the row's heading (PipelineParams::row_align_*),
// scored against the scene's ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "romo/core/angles.hpp"
#include "romo/core/statistics.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::pipeline {
namespace {

// The approach toward the first rows and along the aisle (seed 1, `romo run`'s default scene):
// frames 0-11 of 40.
constexpr int kFrames = 12;
constexpr double kNearM = 8.0, kFarM = 15.0;  // row_align_min_range_m .. the scored range
constexpr double kMatchM = 1.5;               // SceneEvalParams::car_match_m

constexpr double kAlongDeg = 10.0;           // a box this near the car's heading is along it

struct FarCarScore {
  int truths = 0, matched = 0;
  int along = 0;                    // matched boxes within kAlongDeg of the car's heading
  std::vector<double> yaw_err_deg;  // of the matched boxes
};

// Truth cars kNearM..kFarM from the vehicle and the nearest measured car box to each.
void Score(const sim::GroundTruth& gt, const FrameResult& r, FarCarScore* score) {
  const Eigen::Isometry3d T_vehicle_world = gt.T_world_vehicle.inverse();
  for (const sim::GtBox& truth : gt.objects) {
    if (truth.class_name != "car") continue;
    const Eigen::Vector2d c = (T_vehicle_world * truth.center_m).head<2>();
    if (c.norm() < kNearM || c.norm() > kFarM) continue;
    const Eigen::Vector3d axis = T_vehicle_world.linear() * Eigen::Vector3d(std::cos(truth.yaw_rad), std::sin(truth.yaw_rad), 0);
    ++score->truths;
    const planning_iface::Obstacle* nearest = nullptr;
    for (const auto& o : r.obstacles.obstacles) {
      if (o.class_name != "car" || o.num_points == 0) continue;
      if (nearest == nullptr || (o.center_m.head<2>() - c).norm() < (nearest->center_m.head<2>() - c).norm()) nearest = &o;
    }
    if (nearest == nullptr || (nearest->center_m.head<2>() - c).norm() > kMatchM) continue;
    ++score->matched;
    score->yaw_err_deg.push_back(AxisAngleDeg(nearest->yaw_rad, std::atan2(axis.y(), axis.x())));
    score->along += score->yaw_err_deg.back() <= kAlongDeg;
  }
}

TEST(RowAlignTest, FarCarsSeenObliquelyInARowAreBoxedAlongIt) {
  sim::RegisterSimSource();
  auto source = drivers::OpenSource("sim://parking?seed=1&frames=40&scale=0.5&rate_hz=2.7&threads=2");
  auto* sim_source = dynamic_cast<sim::SimSource*>(source.get());
  ASSERT_NE(sim_source, nullptr);
  const drivers::Calibration calibration = *source->calibration();
  // The row's paint (bays_from_paint) heads these boxes too: off here, so that the row's heading
  // from its cars is what is measured, and on (the default) for what the two give together.
  const PipelineParams painted = PipelineParams::ForCalibration(calibration, 2);
  PipelineParams aligned = painted;
  aligned.bays_from_paint = false;
  PipelineParams unaligned = aligned;
  unaligned.row_align_min_cars = 0;
  FarCarScore with_row, without_row, with_paint;
  for (int f = 0; f < kFrames; ++f) {
    const std::optional<drivers::FrameSet> frames = source->Next();
    ASSERT_TRUE(frames.has_value());
    Score(sim_source->ground_truth(), Pipeline(calibration, aligned).Process(*frames), &with_row);
    Score(sim_source->ground_truth(), Pipeline(calibration, unaligned).Process(*frames), &without_row);
    Score(sim_source->ground_truth(), Pipeline(calibration, painted).Process(*frames), &with_paint);
  }
  std::printf("FIGURE row align: with the row's paint too, matched %d/%d, boxed within %.0f deg %d, yaw error median "
              "%.1f deg\n",
              with_paint.matched, with_paint.truths, kAlongDeg, with_paint.along, Median(with_paint.yaw_err_deg));
  std::printf("FIGURE row align: far cars (%.0f-%.0f m) matched %d/%d with the row's heading, %d/%d without; "
              "boxed within %.0f deg of the car %d and %d; yaw error median %.1f deg with, %.1f without\n",
              kNearM, kFarM, with_row.matched, with_row.truths, without_row.matched, without_row.truths, kAlongDeg,
              with_row.along, without_row.along, Median(with_row.yaw_err_deg), Median(without_row.yaw_err_deg));
  ASSERT_EQ(with_row.truths, without_row.truths);
  ASSERT_GE(with_row.truths, 40) << "the approach must pass enough far cars for this test";
  // Measured: 49 and 47 of 67 matched, 22 and 18 boxed along the car, yaw 14.1 and 15.7 deg (a
  // refit whose completed footprint covers ground seen is not taken, so many far views keep
  // their box). Each frame is deterministic for a build; the margins cover compiler and library
  // differences in floating point.
  ASSERT_GE(Median(without_row.yaw_err_deg), 12.0) << "without the row, far boxes follow the sight lines";
  EXPECT_GE(with_row.matched, without_row.matched + 1);
  EXPECT_GE(with_row.along, without_row.along + 3);
  EXPECT_LT(Median(with_row.yaw_err_deg), Median(without_row.yaw_err_deg) - 0.5);
  // Measured with the paint: 58 of 67 matched, 39 along, yaw 5.4 deg.
  EXPECT_GE(with_paint.matched, with_row.matched);
  EXPECT_GE(with_paint.along, with_row.along + 10);
  EXPECT_LT(Median(with_paint.yaw_err_deg), 0.5 * Median(with_row.yaw_err_deg));
}

}  // namespace
}  // namespace romo::pipeline
