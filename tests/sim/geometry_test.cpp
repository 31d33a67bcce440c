// Rendered geometry against an independent camera model: ground-truth 3D points projected by
// OpenCV (cv::projectPoints, with the calibration's distortion) land where the rendered depth
// and disparity say they are, in the left and the right image of every rig.
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "camera_projection.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::sim {
namespace {

// Sub-pixel agreement: the projected point may sit at most this far (px, along the image's
// depth gradient) from where the rendered disparity puts it; measured ~5e-5 px (float depth).
constexpr double kMaxImpliedErrorPx = 0.01;
// Bilinear interpolation of disparity on a plane is exact up to lens distortion curvature
// (measured ~1e-5 px at k1 = -0.02).
constexpr double kMaxDisparityErrorPx = 0.002;
// Only use ground points where disparity changes fast enough along v to locate them.
constexpr double kMinDisparityGradient = 0.02;  // px per px
constexpr int kMinPointsPerCamera = 20;
// Faces seen at more than ~70 degrees from their normal are skipped (see CheckRig).
constexpr double kMinViewCosine = 0.35;

struct Sample {
  double disparity_px = 0.0;
  double gradient_v = 0.0;  // d disparity / dv
  bool ok = false;
};

// Disparity (from rendered depth) bilinearly interpolated at (u, v), only where all four
// neighbours see object @p id.
Sample SampleDisparity(const std::vector<float>& depth, const std::vector<std::int16_t>& ids,
                       int width, int height, double u, double v, int id, double fb) {
  Sample s;
  const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
  if (x0 < 1 || y0 < 1 || x0 + 2 >= width || y0 + 2 >= height) return s;
  auto d = [&](int x, int y) { return fb / depth[static_cast<std::size_t>(y) * width + x]; };
  for (int y = y0 - 1; y <= y0 + 2; ++y) {
    for (int x = x0; x <= x0 + 1; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      if (ids[i] != id || depth[i] <= 0.f) return s;
    }
  }
  const double ax = u - x0, ay = v - y0;
  s.disparity_px = (1 - ay) * ((1 - ax) * d(x0, y0) + ax * d(x0 + 1, y0)) +
                   ay * ((1 - ax) * d(x0, y0 + 1) + ax * d(x0 + 1, y0 + 1));
  s.gradient_v = 0.5 * (d(x0, y0 + 2) - d(x0, y0 - 1)) / 1.5;
  s.ok = true;
  return s;
}

struct TruthPoint {
  Eigen::Vector3d p_world;
  Eigen::Vector3d normal_world;  // outward: the point is visible only from this side
  int id;
};

// Ground-truth points: a grid on the ground and grids on every face of every object (away from
// the face borders, where the surface bends).
std::vector<TruthPoint> TruthPoints(const GroundTruth& truth) {
  std::vector<TruthPoint> pts;
  const Eigen::Vector3d ego = truth.T_world_vehicle.translation();
  for (double x = -12; x <= 12; x += 0.37) {
    for (double y = -12; y <= 12; y += 0.37) {
      pts.push_back({ego + Eigen::Vector3d(x, y, -ego.z()), Eigen::Vector3d::UnitZ(), kGroundId});
    }
  }
  for (const GtBox& b : truth.objects) {
    const double c = std::cos(b.yaw_rad), s = std::sin(b.yaw_rad);
    auto world = [&](double lx, double ly, double lz) {
      return Eigen::Vector3d(b.center_m.x() + c * lx - s * ly, b.center_m.y() + s * lx + c * ly,
                             b.center_m.z() + lz);
    };
    const Eigen::Vector3d h = b.size_m / 2;
    const Eigen::Vector3d ax(c, s, 0), ay(-s, c, 0);
    for (double a = -0.6; a <= 0.61; a += 0.15) {
      for (double z = -0.6; z <= 0.61; z += 0.15) {
        for (int sign : {-1, 1}) {
          pts.push_back({world(sign * h.x(), a * h.y(), z * h.z()), sign * ax, b.id});
          pts.push_back({world(a * h.x(), sign * h.y(), z * h.z()), sign * ay, b.id});
        }
        pts.push_back({world(a * h.x(), z * h.y(), h.z()), Eigen::Vector3d::UnitZ(), b.id});
      }
    }
  }
  return pts;
}

struct Stats {
  int checked = 0;
  double max_implied_px = 0.0;
  double max_disparity_err_px = 0.0;
};

void CheckRig(const drivers::RigCalibration& rig, const GtDepth& depth, const GroundTruth& truth,
              bool rectified, Stats* left_stats, Stats* right_stats) {
  const double fb = rig.left.K(0, 0) * rig.baseline_m();
  const Eigen::Isometry3d T_left_world = (truth.T_world_vehicle * rig.T_vehicle_rig).inverse();
  Eigen::Isometry3d T_right_left = Eigen::Isometry3d::Identity();
  T_right_left.linear() = rig.R;
  T_right_left.translation() = rig.T;
  const Eigen::Vector3d left_centre = T_left_world.inverse().translation();
  const Eigen::Vector3d right_centre = (T_right_left * T_left_world).inverse().translation();
  for (const TruthPoint& tp : TruthPoints(truth)) {
    const int id = tp.id;
    const Eigen::Vector3d pl = T_left_world * tp.p_world;
    const Eigen::Vector3d pr = T_right_left * pl;
    if (pl.z() < 0.5 || pr.z() < 0.5) continue;
    // Back faces are hidden by the object's own front; at grazing view a face is only a few
    // pixels wide and the interpolation window would straddle the box's edge.
    const double min_cos = id == kGroundId ? 0.0 : kMinViewCosine;
    if (tp.normal_world.dot((left_centre - tp.p_world).normalized()) <= min_cos ||
        tp.normal_world.dot((right_centre - tp.p_world).normalized()) <= min_cos) {
      continue;
    }
    const cv::Point2d ul = test::ProjectToImage(pl, rig.left), ur = test::ProjectToImage(pr, rig.right);
    const Sample sl = SampleDisparity(depth.left_depth_m, depth.left_object_id, depth.width,
                                      depth.height, ul.x, ul.y, id, fb);
    const Sample sr = SampleDisparity(depth.right_depth_m, depth.right_object_id, depth.width,
                                      depth.height, ur.x, ur.y, id, fb);
    for (int side = 0; side < 2; ++side) {
      const Sample& s = side == 0 ? sl : sr;
      const double z = side == 0 ? pl.z() : pr.z();
      Stats* st = side == 0 ? left_stats : right_stats;
      if (!s.ok) continue;  // occluded, outside, or at an object edge
      const double err = std::abs(s.disparity_px - fb / z);
      st->max_disparity_err_px = std::max(st->max_disparity_err_px, err);
      EXPECT_LT(err, kMaxDisparityErrorPx) << "rig " << rig.name << (side ? " right" : " left")
                                           << " object " << id << " depth " << z;
      if (id == kGroundId && std::abs(s.gradient_v) > kMinDisparityGradient) {
        const double implied = err / std::abs(s.gradient_v);
        st->max_implied_px = std::max(st->max_implied_px, implied);
        EXPECT_LT(implied, kMaxImpliedErrorPx) << "rig " << rig.name << " ground point";
      }
      ++st->checked;
    }
    if (rectified && sl.ok) {
      // Without distortion and R = I, the rigs are rectified: the horizontal offset of the two
      // projections is the disparity the rendered depth gives.
      EXPECT_NEAR(ul.x - ur.x, sl.disparity_px, kMaxDisparityErrorPx) << "rig " << rig.name;
      EXPECT_NEAR(ul.y, ur.y, 1e-6);
    }
  }
}

void RunGeometry(const std::string& uri_text, bool rectified) {
  SimSource source(SimParams::FromUri(drivers::Uri::Parse(uri_text)));
  const auto frames = source.Next();
  ASSERT_TRUE(frames.has_value());
  const GroundTruth& truth = source.ground_truth();
  ASSERT_EQ(source.depth().size(), source.calibration()->rigs.size());
  for (std::size_t r = 0; r < source.calibration()->rigs.size(); ++r) {
    const auto& rig = source.calibration()->rigs[r];
    Stats left, right;
    CheckRig(rig, source.depth()[r], truth, rectified, &left, &right);
    EXPECT_GE(left.checked, kMinPointsPerCamera) << rig.name;
    EXPECT_GE(right.checked, kMinPointsPerCamera) << rig.name;
    std::printf("rig %-11s points L/R %4d/%4d  max disparity error %.1e/%.1e px  max implied "
                "offset %.1e/%.1e px\n",
                rig.name.c_str(), left.checked, right.checked, left.max_disparity_err_px,
                right.max_disparity_err_px, left.max_implied_px, right.max_implied_px);
  }
}

// Frame 95: the ego has turned in front of the bay, pedestrians stand and walk around it.
TEST(SimGeometryTest, TruthPointsProjectWhereRenderedDepthSaysWithDistortion) {
  RunGeometry("sim://parking?seed=4&frames=1&first=95&scale=0.5&depth=1&aa=1&noise=0", false);
}

TEST(SimGeometryTest, RectifiedDisparityMatchesProjectionOffsetWithoutDistortion) {
  RunGeometry("sim://parking?seed=4&frames=1&first=40&scale=0.5&depth=1&aa=1&noise=0&distortion=0",
              true);
}

}  // namespace
}  // namespace romo::sim
