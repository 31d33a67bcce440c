// The blob map inside the manipulation plugin: a simulated drinking scene with a box ("prop")
// behind the mouth position, so the raised hand hides part of it part of the time. The box of
// the fused, highest-confidence points must be closer to the prop's true size than the boxes of
// single frames, and the confidence of points seen again and again must rise.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "romo/indoor_manip/knowledge.hpp"
#include "romo/indoor_manip/manip_analyzer.hpp"
#include "romo/indoor_manip/manip_session.hpp"
#include "romo/indoor_manip/object_map.hpp"
#include "romo/indoor_manip/rgbd_image.hpp"
#include "romo/indoor_manip/scene_objects.hpp"
#include "romo/sim_manip/manip_eval.hpp"
#include "romo/sim_manip/sim_manip.hpp"

namespace romo::indoor_manip {
namespace {

// Size error of a box against the truth, extents compared largest to largest.
double SizeError(const objects::Box3& box, const Eigen::Vector3d& truth_m) {
  Eigen::Vector3d a = box.size.cast<double>(), b = truth_m;
  std::sort(a.data(), a.data() + 3);
  std::sort(b.data(), b.data() + 3);
  return (a - b).norm();
}

// The scene object nearest @p centre (camera frame), or -1 when none lies within 10 cm.
int NearestObject(const SceneGeometry& g, const Eigen::Vector3d& centre) {
  int best = -1;
  double best_d = 0.10;
  for (std::size_t i = 0; i < g.objects.size(); ++i) {
    if (g.objects[i].is_hand) continue;
    const double d = (g.objects[i].box.center.cast<double>() - centre).norm();
    if (d < best_d) {
      best_d = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

sim_manip::SimManipOptions PropScene() {
  sim_manip::SimManipOptions o;
  o.action = "drinking";
  o.seed = 21;  // seeds 3, 7 and 50 measured alike (completed 3.4-4.1 mm, single-frame median 9 mm)
  o.prop = true;
  return o;
}

TEST(ObjectMapTest, FusedPropBoxBeatsSingleFramesUnderHandOcclusion) {
  const sim_manip::SimManipScene scene(PropScene());
  const auto& truth = scene.truth();
  ASSERT_EQ(truth.objects.back().name, "prop");
  const sim_manip::SimObjectTruth& prop = truth.objects.back();
  const InteractionPlane plane = InteractionPlane::FromCoefficients(truth.plane_camera);
  const DepthIntrinsics k{truth.K(0, 0), truth.K(1, 1), truth.K(0, 2), truth.K(1, 2)};
  const SceneObjectParams sp;
  ObjectMapParams mp;
  mp.every_frames = 1;
  ObjectMap map(k, plane, mp, OdometryParams{});

  std::vector<objects::Box3> single_boxes;
  objects::Box3 first_pca_box;
  std::vector<int> single_points;
  std::vector<double> mean_cv;  // the prop's stored points, after each fused frame
  int prop_blob = -1;
  for (int f = 0; f < scene.frame_count(); ++f) {
    const RgbdImage image = ToRgbdImage(scene.Render(f), "sim-manip");
    SceneGeometry g = SegmentSceneObjects(image, k, plane, cv::Point(-1, -1), sp);
    // The hand's blob is the one around the true hand centre (the plugin marks it by its seed).
    for (auto& o : g.objects) o.is_hand = (o.box.center.cast<double>() - truth.hand_centre_camera_m[f]).norm() < 0.06;
    const int o = NearestObject(g, prop.centre_camera_m);
    if (o >= 0) {
      // The single frame's box made the same way as the completed one (standing on the plane).
      const Eigen::Matrix3Xf cloud = OrganizedCloud(image, k);
      const objects::Box3 box = objects::FitVerticalBox(cloud, g.objects[o].pixels, plane.normal.cast<float>());
      if (single_boxes.empty()) first_pca_box = g.objects[o].box;
      single_boxes.push_back(box);
      single_points.push_back(g.objects[o].points);
    }
    if (!map.Add(image, g)) continue;
    if (prop_blob < 0) {
      for (const auto& c : map.Completed()) {
        if (o >= 0 && c.first_frame_object == g.objects[o].id) prop_blob = c.blob_id;
      }
    }
    for (const auto& c : map.Completed()) {
      if (c.blob_id == prop_blob) mean_cv.push_back(c.mean_confidence);
    }
  }
  ASSERT_GE(prop_blob, 0);
  // Frames without an ego-motion (too few static features) are left out, not fused wrongly.
  std::printf("fused %d of %d frames, %d without ego-motion, %d rekeys\n", map.stats().frames_fused,
              scene.frame_count(), map.stats().ego_failures, map.stats().rekeys);
  EXPECT_GE(map.stats().frames_fused, scene.frame_count() - 10);
  // The camera does not move: the last pose moves the prop's centre by less than a centimetre
  // (measured ego-motion scatter at the prop: median 2 mm, worst 8.5 mm over the frames).
  constexpr double kMaxPoseDisplacementM = 0.01;
  EXPECT_LT((map.T_world_camera() * prop.centre_camera_m - prop.centre_camera_m).norm(), kMaxPoseDisplacementM);

  // The part of the prop the geometric layer can see: above the foreground height.
  const Eigen::Vector3d visible_m = prop.size_m - Eigen::Vector3d(0, 0, sp.min_height_m);
  CompletedObject completed;
  for (const auto& c : map.Completed()) {
    if (c.blob_id == prop_blob) completed = c;
  }
  ASSERT_TRUE(completed.completed_box.has_value());
  const double err_completed = SizeError(*completed.completed_box, visible_m);
  std::vector<double> all_err, hidden_err;
  const int max_pts = *std::max_element(single_points.begin(), single_points.end());
  for (std::size_t f = 0; f < single_boxes.size(); ++f) {
    const double e = SizeError(single_boxes[f], visible_m);
    all_err.push_back(e);
    // The hand hides part of the prop: a tenth of its pixels or more are missing.
    if (single_points[f] < 0.9 * max_pts) hidden_err.push_back(e);
  }
  std::printf("prop visible size %.3f x %.3f x %.3f m; completed box %.3f x %.3f x %.3f m from %d of %d points\n",
              visible_m.x(), visible_m.y(), visible_m.z(), completed.completed_box->size.x(),
              completed.completed_box->size.y(), completed.completed_box->size.z(), completed.completed_points,
              completed.points);
  ASSERT_GE(hidden_err.size(), 5u) << "the hand hid part of the prop in too few frames";
  const double hidden_median = Median(hidden_err), all_median = Median(all_err);
  std::printf("size error: completed %.4f m; single frames: first %.4f, median %.4f (all %zu), "
              "median %.4f (%zu with a tenth or more hidden), worst %.4f m\n",
              err_completed, all_err.front(), all_median, all_err.size(), hidden_median, hidden_err.size(),
              *std::max_element(all_err.begin(), all_err.end()));
  std::printf("PCA boxes: completed %.4f m, first frame %.4f m\n", SizeError(*completed.completed_pca_box, visible_m),
              SizeError(first_pca_box, visible_m));
  std::printf("bands [0,.25) [.25,.5) [.5,.75) [.75,1]: %d %d %d %d, mean CV %.3f\n", completed.points_per_band[0],
              completed.points_per_band[1], completed.points_per_band[2], completed.points_per_band[3],
              completed.mean_confidence);
  // Single frames are ~9 mm off (mixed pixels at the depth edges widen the footprint), also where
  // the hand hides part of the prop (it hides the middle, not the ends); the fused points with
  // CV >= 0.75 keep the edges that are seen again and again: measured 3.0 mm (seed 21).
  EXPECT_LT(err_completed, hidden_median);
  EXPECT_LT(err_completed, all_median);
  constexpr double kMaxCompletedErrM = 0.006;
  EXPECT_LT(err_completed, kMaxCompletedErrM);

  // Confidence rises with repeated sightings: from 1 - exp(-1/2) = 0.39 for the first frame's
  // points to most of the way to 1.
  ASSERT_GE(mean_cv.size(), 10u);
  std::printf("prop mean CV: frame 0 %.3f, frame 1 %.3f, frame 5 %.3f, last %.3f\n", mean_cv[0], mean_cv[1],
              mean_cv[5], mean_cv.back());
  EXPECT_NEAR(mean_cv[0], 1 - std::exp(-0.5), 1e-9);
  EXPECT_GT(mean_cv[5], mean_cv[1]);
  EXPECT_GT(mean_cv[1], mean_cv[0]);
  EXPECT_GT(completed.points_per_band[3], completed.points / 2);
}

}  // namespace
}  // namespace romo::indoor_manip
