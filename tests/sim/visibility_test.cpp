// What the rigs can see of ground-truth objects (the eval's "visible" scores), on a hand-made
// scene and against the renderer's own per-pixel object ids.
#include "romo/sim/visibility.hpp"

#include <cstdio>
#include <map>

#include <gtest/gtest.h>

#include "romo/drivers/frame_source.hpp"
#include "romo/sim/renderer.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::sim {
namespace {

GtBox Box(int id, const char* cls, double x, double y, double length, double width, double height) {
  GtBox b;
  b.id = id;
  b.class_name = cls;
  b.center_m = Eigen::Vector3d(x, y, height / 2);
  b.size_m = Eigen::Vector3d(length, width, height);
  return b;
}

TEST(VisibilityTest, AWallBetweenHidesACarAndOnlyTheTopShowsOverALowOne) {
  const drivers::Calibration calibration =
      ScaleCalibration(drivers::Calibration::Load(drivers::SampleCalibrationPath()), 0.25);
  const Eigen::Isometry3d at_origin = Eigen::Isometry3d::Identity();
  const GtBox car = Box(100, "car", 10.0, 0.0, 4.4, 1.8, 1.5);
  const double open = VisibleFraction(car, {car}, calibration, at_origin);
  // Seen from the front rig: its rear face and top; the sides only at grazing angles.
  EXPECT_GT(open, 0.5);
  const GtBox wall = Box(2, "wall", 5.0, 0.0, 0.3, 6.0, 3.0);
  EXPECT_EQ(VisibleFraction(car, {car, wall}, calibration, at_origin), 0.0);
  const GtBox curb = Box(1, "curb", 5.0, 0.0, 0.3, 6.0, 0.15);
  EXPECT_DOUBLE_EQ(VisibleFraction(car, {car, curb}, calibration, at_origin), open);
  // Half height: the upper part of the rear face and the top stay in view.
  const GtBox low = Box(3, "wall", 5.0, 0.0, 0.3, 6.0, 1.0);
  const double over_low = VisibleFraction(car, {car, low}, calibration, at_origin);
  EXPECT_GT(over_low, 0.1);
  EXPECT_LT(over_low, open);
}

TEST(VisibilityTest, AgreesWithTheRenderersObjectIds) {
  RegisterSimSource();
  auto source = drivers::OpenSource("sim://parking?seed=1&frames=4&scale=0.25&depth=1&threads=2");
  auto* sim = dynamic_cast<SimSource*>(source.get());
  ASSERT_NE(sim, nullptr);
  int visible = 0, hidden = 0;
  while (auto set = source->Next()) {
    const GroundTruth& truth = sim->ground_truth();
    std::map<int, int> pixels;  // object id -> left-image pixels showing it, over all rigs
    for (const GtDepth& d : sim->depth()) {
      for (std::int16_t id : d.left_object_id) ++pixels[id];
    }
    for (const GtBox& o : truth.objects) {
      if (o.class_name != "car" && o.class_name != "pedestrian") continue;
      const double fraction = VisibleFraction(o, truth.objects, *source->calibration(), truth.T_world_vehicle);
      // A quarter of the surface in view shows in the images (a pedestrian 15 m away at quarter
      // resolution still covers ~30 pixels).
      if (fraction >= 0.25) {
        ++visible;
        EXPECT_GT(pixels[o.id], 0) << o.class_name << " " << o.id << " fraction " << fraction;
      } else {
        ++hidden;
      }
      // Nothing in any image: nothing in view (samples are a 6 x 6 grid a face, so a sliver
      // between grid points may be missed, never the reverse).
      if (pixels[o.id] == 0) {
        EXPECT_EQ(fraction, 0.0) << o.class_name << " " << o.id;
      }
    }
  }
  std::printf("visible %d, hidden %d object sightings\n", visible, hidden);
  EXPECT_GT(visible, 0);
  EXPECT_GT(hidden, 0);
}

}  // namespace
}  // namespace romo::sim
