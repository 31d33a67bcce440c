// Classification and completion of boxes seen from one viewpoint (only the near faces visible).
#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/objects/atlas.hpp"
#include "romo/objects/view_completion.hpp"
#include "test_support.hpp"

namespace romo::objects {
namespace {

constexpr float kPi = 3.14159265358979f;

Atlas Load() { return Atlas::Load(test::SourcePath("config/atlas.yaml")); }

std::string NameOf(const Atlas& atlas, const Classification& c) {
  return atlas.classes()[static_cast<std::size_t>(c.class_index)].name;
}

Box3 MakeBox(Eigen::Vector2f center, float length, float width, float height, float yaw) {
  Box3 b;
  b.center = Eigen::Vector3f(center.x(), center.y(), height / 2);
  b.size = Eigen::Vector3f(length, width, height);
  b.yaw_rad = yaw;
  b.axes.col(0) = Eigen::Vector3f(std::cos(yaw), std::sin(yaw), 0);
  b.axes.col(1) = Eigen::Vector3f(-std::sin(yaw), std::cos(yaw), 0);
  b.axes.col(2) = Eigen::Vector3f::UnitZ();
  return b;
}

TEST(ViewCompletionTest, FrontOfACarIsCompletedAwayFromTheViewer) {
  const Atlas atlas = Load();
  const double car_length = atlas.classes()[atlas.Require("car")].length.mean_m;
  // Stereo saw the front 0.5 m of a car whose front face is 11 m ahead: 1.8 m across the line of
  // sight (box length axis along y), 0.5 m along it.
  const Box3 seen = MakeBox({11.25f, 0.f}, 1.8f, 0.5f, 1.5f, kPi / 2);
  const ViewedBox v = ClassifyFromViewpoint(atlas, seen, Eigen::Vector2f::Zero());
  EXPECT_EQ(NameOf(atlas, v.classification), "car");
  ASSERT_TRUE(v.completed);
  // The length now runs along the line of sight; the near face (x = 11) stays put.
  EXPECT_NEAR(v.box.size.x(), car_length, 1e-5);
  EXPECT_NEAR(v.box.size.y(), 1.8, 1e-5);
  EXPECT_NEAR(v.box.center.x(), 11.0 + car_length / 2, 1e-5);
  EXPECT_NEAR(v.box.center.y(), 0.0, 1e-5);
  EXPECT_NEAR(std::abs(std::cos(v.box.yaw_rad)), 1.0, 1e-5);
  // axes.col(0) still points along the (new) length and the frame stays right-handed.
  EXPECT_NEAR(std::abs(v.box.axes.col(0).x()), 1.0, 1e-5);
  EXPECT_NEAR(v.box.axes.col(0).cross(v.box.axes.col(1)).z(), 1.0, 1e-5);
}

TEST(ViewCompletionTest, SideOfACarBehindTheViewerGrowsBackwards) {
  const Atlas atlas = Load();
  const double car_width = atlas.classes()[atlas.Require("car")].width.mean_m;
  // A car broadside 8 m behind (x = -8): its 4.3 m side seen, 0.4 m of its width.
  const Box3 seen = MakeBox({-8.2f, 1.f}, 4.3f, 0.4f, 1.45f, kPi / 2);
  const ViewedBox v = ClassifyFromViewpoint(atlas, seen, Eigen::Vector2f::Zero());
  EXPECT_EQ(NameOf(atlas, v.classification), "car");
  ASSERT_TRUE(v.completed);
  EXPECT_NEAR(v.box.size.y(), car_width, 1e-5);
  EXPECT_NEAR(v.box.center.x(), -8.0 - car_width / 2, 1e-5);  // near face at x = -8 kept
  EXPECT_NEAR(v.box.center.y(), 1.0, 1e-5);
}

TEST(ViewCompletionTest, PedestrianIsNotACarEvenWhenTruncated) {
  const Atlas atlas = Load();
  const ViewedBox v = ClassifyFromViewpoint(atlas, MakeBox({6.f, 2.f}, 0.5f, 0.3f, 1.75f, 1.2f),
                                            Eigen::Vector2f::Zero());
  EXPECT_EQ(NameOf(atlas, v.classification), "pedestrian");
  // Shorter than the pedestrian mean along the line of sight: completed a little, never more
  // than to the class mean.
  EXPECT_LE(v.box.size.head<2>().maxCoeff(), atlas.classes()[atlas.Require("pedestrian")].length.mean_m + 1e-5);
}

TEST(ViewCompletionTest, CornerViewsAndImplausibleBoxesAreNotCompleted) {
  const Atlas atlas = Load();
  // Seen at 45 degrees both faces are visible whole: a 2 m x 1 m footprint is no car.
  const ViewedBox corner =
      ClassifyFromViewpoint(atlas, MakeBox({7.f, 7.f}, 2.0f, 1.0f, 1.5f, 0.f), Eigen::Vector2f::Zero());
  EXPECT_NE(NameOf(atlas, corner.classification), "car");
  EXPECT_FALSE(corner.completed);
  // Wider across the line of sight than any class: unknown, box unchanged.
  const Box3 wall = MakeBox({10.f, 0.f}, 9.0f, 0.5f, 1.4f, kPi / 2);
  const ViewedBox w = ClassifyFromViewpoint(atlas, wall, Eigen::Vector2f::Zero());
  EXPECT_EQ(NameOf(atlas, w.classification), "unknown");
  EXPECT_FALSE(w.completed);
  EXPECT_TRUE(w.box.center.isApprox(wall.center));
}

TEST(ViewCompletionTest, CornerReadingsLetEitherSideBeTheCutOne) {
  const Atlas atlas = Load();
  // A parked car's end (1.75 m, along y) and the 1.65 m of its side a neighbour leaves in view,
  // seen from the origin 41 degrees off the side: just outside the 40 degree truncation cone, so
  // by default both faces read as whole and 1.65 x 1.75 m is no car.
  const float at = 41.f * kPi / 180.f;
  const Box3 seen = MakeBox({6.f * std::cos(at), 6.f * std::sin(at)}, 1.65f, 1.75f, 1.45f, 0.f);
  const ViewedBox whole = ClassifyFromViewpoint(atlas, seen, Eigen::Vector2f::Zero());
  EXPECT_NE(NameOf(atlas, whole.classification), "car");
  EXPECT_FALSE(whole.completed);

  ViewCompletionParams corner;
  corner.corner_angle_deg = 50.0;
  const ViewedBox cut = ClassifyFromViewpoint(atlas, seen, Eigen::Vector2f::Zero(), corner);
  EXPECT_EQ(NameOf(atlas, cut.classification), "car");
  ASSERT_TRUE(cut.completed);
  // The side (x axis, 1.65 m) was the cut one: completed to the car mean away from the viewer,
  // its near end kept; the end's 1.75 m stays the width.
  const double car_length = atlas.classes()[atlas.Require("car")].length.mean_m;
  EXPECT_NEAR(cut.box.size.x(), car_length, 1e-5);
  EXPECT_NEAR(cut.box.size.y(), 1.75, 1e-5);
  EXPECT_NEAR(cut.box.center.x(), seen.center.x() - 0.825 + car_length / 2, 1e-4);
  EXPECT_NEAR(cut.box.center.y(), seen.center.y(), 1e-5);
  // Exactly at a corner (45 degrees) the default still reads both faces as whole.
  const float diagonal = kPi / 4;
  const Box3 at_45 = MakeBox({6.f * std::cos(diagonal), 6.f * std::sin(diagonal)}, 1.65f, 1.75f, 1.45f, 0.f);
  EXPECT_FALSE(ClassifyFromViewpoint(atlas, at_45, Eigen::Vector2f::Zero()).completed);
  EXPECT_TRUE(ClassifyFromViewpoint(atlas, at_45, Eigen::Vector2f::Zero(), corner).completed);
}

TEST(ViewCompletionTest, ViewpointDecidesWhichFaceWasSeen) {
  const Atlas atlas = Load();
  // The front 0.9 m of a car (its front and the start of a side), 1.8 m across, at (3, 3): from
  // the vehicle origin the line of sight is at 45 degrees to both axes (no face is truncated, and
  // 0.9 m is too narrow for anything car-like; too deep for a lone face); from a corner camera at
  // (3, 0) it runs straight along the box's y axis.
  const Box3 seen = MakeBox({3.f, 3.45f}, 1.8f, 0.9f, 1.5f, 0.f);
  EXPECT_FALSE(ClassifyFromViewpoint(atlas, seen, Eigen::Vector2f::Zero()).completed);
  const ViewedBox v = ClassifyFromViewpoint(atlas, seen, Eigen::Vector2f(3.f, 0.f));
  EXPECT_EQ(NameOf(atlas, v.classification), "car");
  ASSERT_TRUE(v.completed);
  const double car_length = atlas.classes()[atlas.Require("car")].length.mean_m;
  EXPECT_NEAR(v.box.center.y(), 3.0 + car_length / 2, 1e-5);  // the near face (y = 3) kept
}

TEST(ViewCompletionTest, ALoneFaceSeenObliquelyIsCompletedAlongItsNormal) {
  const Atlas atlas = Load();
  const double car_length = atlas.classes()[atlas.Require("car")].length.mean_m;
  // A car's rear, 1.9 m across and 0.2 m deep, its side hidden by the next car, seen by a side
  // camera at (1.5, 1) with the sight line 73 degrees off the face's normal (x): nearest the
  // width axis. Read along the sight line it is nothing (0.2 m wide); read as a face it is a car
  // reaching away from the camera along x.
  const Box3 rear = MakeBox({2.9f, 5.3f}, 1.9f, 0.2f, 1.4f, kPi / 2);
  const Eigen::Vector2f side_camera(1.5f, 1.f);
  const ViewedBox v = ClassifyFromViewpoint(atlas, rear, side_camera);
  EXPECT_EQ(NameOf(atlas, v.classification), "car");
  ASSERT_TRUE(v.completed);
  EXPECT_NEAR(v.box.center.x(), 2.8 + car_length / 2, 1e-5);  // the near face (x = 2.8) kept
  EXPECT_NEAR(v.box.center.y(), 5.3, 1e-5);
  EXPECT_NEAR(v.box.size.x(), car_length, 1e-5);
  EXPECT_NEAR(v.box.size.y(), 1.9, 1e-5);
  // Two people one behind the other along the same sight line make a blob of about that shape
  // (1.2 m along the sight line, 0.3 m across, 1.7 m tall): both readings compete and the tall,
  // narrow blob is not read as a car's face (a car 1.2 m wide and 1.7 m tall explains it worse
  // than a cyclist seen end-on does).
  const Box3 pair = MakeBox({1.2f, 5.f}, 1.2f, 0.3f, 1.7f, 1.2f);
  EXPECT_NE(NameOf(atlas, ClassifyFromViewpoint(atlas, pair, side_camera).classification), "car");
  // Too far off its normal (beyond face_max_obliquity_deg) a face is not read as one.
  ViewCompletionParams grazing;
  grazing.face_max_obliquity_deg = 60.0;
  EXPECT_FALSE(ClassifyFromViewpoint(atlas, rear, side_camera, grazing).completed);
}

TEST(ViewCompletionTest, CompletingAsAKnownClassKeepsTheNearFaceOrSaysUnknown) {
  const Atlas atlas = Load();
  const int car = atlas.Require("car");
  const double car_length = atlas.classes()[static_cast<std::size_t>(car)].length.mean_m;
  // A car's front, 1.5 m across (its side cut by the image border), 0.4 m deep, 1.4 m tall, whose
  // track has been a car: completed along the line of sight to a car's length.
  const Box3 front = MakeBox({9.2f, 0.f}, 1.5f, 0.4f, 1.4f, kPi / 2);
  const ViewedBox as_car = CompleteAsClass(atlas, car, front, Eigen::Vector2f::Zero());
  EXPECT_EQ(as_car.classification.class_index, car);
  ASSERT_TRUE(as_car.completed);
  EXPECT_NEAR(as_car.box.size.x(), car_length, 1e-5);
  EXPECT_NEAR(as_car.box.center.x(), 9.0 + car_length / 2, 1e-5);
  EXPECT_GE(as_car.classification.score, atlas.min_score());
  // A fragment 0.6 m tall cannot be any part of a car standing on the ground: unknown, unchanged.
  const Box3 fragment = MakeBox({7.f, 1.f}, 0.6f, 0.1f, 0.6f, 0.f);
  const ViewedBox f = CompleteAsClass(atlas, car, fragment, Eigen::Vector2f::Zero());
  EXPECT_EQ(f.classification.class_index, atlas.unknown_index());
  EXPECT_FALSE(f.completed);
  EXPECT_TRUE(f.box.center.isApprox(fragment.center));
  EXPECT_THROW(CompleteAsClass(atlas, 99, front, Eigen::Vector2f::Zero()), romo::Error);
  EXPECT_THROW(CompleteAsClass(atlas, -1, front, Eigen::Vector2f::Zero()), romo::Error);
}

TEST(ViewCompletionTest, AKnownHeadingMakesItsAxisTheLengthAtAnyAngleToTheSightLine) {
  const Atlas atlas = Load();
  const int car = atlas.Require("car");
  const double car_length = atlas.classes()[static_cast<std::size_t>(car)].length.mean_m;
  // A car parked heading along x, its front face 1.8 m wide at x = 6 m, seen from the origin at
  // 55 deg to its axis (its neighbours hide its side): 0.6 m of smeared depth along x.
  const Box3 front = MakeBox({6.3f, 9.f}, 0.6f, 1.8f, 1.4f, 0.f);
  // Alone, the axis nearer the sight line (35 deg) is y, the face's width: read as truncated
  // there, the 0.6 m along x is a car's length or width, too short for either.
  const ViewedBox alone = CompleteAsClass(atlas, car, front, Eigen::Vector2f::Zero());
  EXPECT_EQ(alone.classification.class_index, atlas.unknown_index());
  // With the row's heading (x) the length lies along x and only its near end was seen.
  const ViewedBox in_row = CompleteAsClass(atlas, car, front, Eigen::Vector2f::Zero(), {}, 0.0, 0.0);
  ASSERT_EQ(in_row.classification.class_index, car);
  ASSERT_TRUE(in_row.completed);
  EXPECT_NEAR(std::abs(std::cos(in_row.box.yaw_rad)), 1.0, 1e-5);
  EXPECT_NEAR(in_row.box.size.x(), car_length, 1e-5);
  EXPECT_NEAR(in_row.box.size.y(), 1.8, 1e-5);
  EXPECT_NEAR(in_row.box.center.x(), 6.0 + car_length / 2, 1e-5);  // the near face stays put
  EXPECT_NEAR(in_row.box.center.y(), 9.0, 1e-5);
  EXPECT_THROW(CompleteAsClass(atlas, car, front, Eigen::Vector2f::Zero(), {}, 0.0, NAN), romo::Error);
}

TEST(ViewCompletionTest, NonFiniteInputIsAnError) {
  const Atlas atlas = Load();
  Box3 b = MakeBox({5.f, 0.f}, 1.f, 1.f, 1.f, 0.f);
  b.size.x() = NAN;
  EXPECT_THROW(ClassifyFromViewpoint(atlas, b, Eigen::Vector2f::Zero()), romo::Error);
}

}  // namespace
}  // namespace romo::objects
