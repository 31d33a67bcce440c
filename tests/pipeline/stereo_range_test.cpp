// Stereo depth against the simulator's rendered depth, by range and by the true disparity's
// fraction: the pixel locking of OpenCV's subpixel parabola on the vehicle's own images, and
// what the gradient refinement (SgmParameters::gradient_refine_radius_px) leaves of it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "camera_projection.hpp"
#include "romo/core/statistics.hpp"
#include "romo/drivers/uri.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/sim/sim_source.hpp"
#include "romo/stereo/rectification.hpp"

namespace romo::pipeline {
namespace {

struct RangeErrors {
  std::map<int, std::vector<double>> depth_by_band;     // stereo z - true z, by 2 m band of true z
  std::vector<std::vector<double>> disparity_by_fraction = std::vector<std::vector<double>>(8);
};

// Every stereo point of a few frames of the parking approach whose pixel sees one smooth surface
// (3x3 of the rendered depth within 5 %), against the rendered depth along its ray.
RangeErrors Measure(int refine_radius_px) {
  sim::SimSource source(sim::SimParams::FromUri(drivers::Uri::Parse("sim://parking?seed=1&frames=3&first=5&depth=1&scale=0.5")));
  const drivers::Calibration& calibration = *source.calibration();
  PipelineParams params = PipelineParams::ForCalibration(calibration, 2);
  params.sgm.gradient_refine_radius_px = refine_radius_px;
  Pipeline pipe(calibration, params);
  RangeErrors out;
  while (auto frames = source.Next()) {
    for (const auto& stereo_frame : frames->stereo) {
      const drivers::RigCalibration& rig = calibration.rig(stereo_frame.rig_id);
      const sim::GtDepth* depth = nullptr;
      for (const auto& d : source.depth()) {
        if (d.rig_id == stereo_frame.rig_id) depth = &d;
      }
      if (depth == nullptr) continue;
      const auto in = pipe.Stereo(stereo_frame);
      if (!in) continue;
      const stereo::Rectifier rectifier(rig);
      const Eigen::Matrix3d R_rect_rig = rectifier.geometry().R_rig_rect.transpose();
      const double fb = rectifier.geometry().focal_px * rectifier.geometry().baseline_m;
      const Eigen::Isometry3d T_rig_vehicle = rig.T_vehicle_rig.inverse();
      for (std::size_t i = 0; i < in->cloud.size(); ++i) {
        const Eigen::Vector3d p = T_rig_vehicle * in->cloud.xyz.col(static_cast<Eigen::Index>(i)).cast<double>();
        if (p.z() < 1.0) continue;
        const cv::Point2d uv = test::ProjectToImage(p, rig.left);
        const int u = static_cast<int>(std::lround(uv.x)), v = static_cast<int>(std::lround(uv.y));
        if (u < 1 || v < 1 || u + 1 >= depth->width || v + 1 >= depth->height) continue;
        const std::size_t centre = static_cast<std::size_t>(v) * depth->width + u;
        float lo = 1e9f, hi = 0.f;
        bool one_surface = true;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const std::size_t k = static_cast<std::size_t>(v + dy) * depth->width + (u + dx);
            one_surface = one_surface && depth->left_depth_m[k] > 0.f &&
                          depth->left_object_id[k] == depth->left_object_id[centre];
            lo = std::min(lo, depth->left_depth_m[k]);
            hi = std::max(hi, depth->left_depth_m[k]);
          }
        }
        if (!one_surface || hi - lo > 0.05f * hi) continue;
        const double true_z = depth->left_depth_m[centre];
        out.depth_by_band[static_cast<int>(true_z / 2.0)].push_back(p.z() - true_z);
        // Disparities in the rectified frame, the true one along the same ray.
        const double measured = fb / (R_rect_rig * p).z();
        const double truth = fb / (R_rect_rig * (p * (true_z / p.z()))).z();
        if (truth < 12.0) {  // the far points, where locking costs metres
          out.disparity_by_fraction[static_cast<std::size_t>((truth - std::floor(truth)) * 8) % 8].push_back(measured - truth);
        }
      }
    }
  }
  return out;
}

// Measured (3 frames of seed 1): median disparity error per eighth of the true fraction from
// -0.29 to +0.20 px with the parabola alone, within +-0.04 px refined; median depth error at
// 8-10 m +0.17 -> -0.01 m, at 14-16 m +0.28 -> -0.12 m. Bounds: locking must show without the
// refinement (the premise) and be gone with it, with room for the scene's texture.
TEST(StereoRangeTest, GradientRefinementRemovesPixelLockingOnTheVehiclesImages) {
  const RangeErrors locked = Measure(0);
  const RangeErrors refined = Measure(2);
  double worst_locked = 0.0, worst_refined = 0.0;
  for (std::size_t b = 0; b < 8; ++b) {
    ASSERT_GE(locked.disparity_by_fraction[b].size(), 500u) << "fraction bin " << b;
    ASSERT_GE(refined.disparity_by_fraction[b].size(), 500u) << "fraction bin " << b;
    const double l = Median(locked.disparity_by_fraction[b]), r = Median(refined.disparity_by_fraction[b]);
    std::printf("true fraction %.3f: median disparity error %+.3f px parabola, %+.3f px refined\n", b / 8.0, l, r);
    worst_locked = std::max(worst_locked, std::abs(l));
    worst_refined = std::max(worst_refined, std::abs(r));
  }
  for (const auto& [band, errors] : refined.depth_by_band) {
    const auto it = locked.depth_by_band.find(band);
    if (errors.size() < 200 || it == locked.depth_by_band.end()) continue;
    std::printf("FIGURE range %2d-%2d m: median depth error %+.3f m parabola, %+.3f m refined\n", 2 * band,
                2 * band + 2, Median(it->second), Median(errors));
  }
  EXPECT_GT(worst_locked, 0.15) << "premise: the parabola alone locks";
  EXPECT_LT(worst_refined, 0.08);
}

}  // namespace
}  // namespace romo::pipeline
