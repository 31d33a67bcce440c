// Ground truth against the rendered images: every pixel an object's id marks back-projects into
// that object's truth box; truth survives its LCM encoding; GNSS follows the geodetic origin.
#include "romo/sim/ground_truth.hpp"

#include <cmath>
#include <map>

#include <GeographicLib/LocalCartesian.hpp>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "romo/core/check.hpp"
#include "romo/sim/sim_source.hpp"

namespace romo::sim {
namespace {

// Depth is stored as float: relative rounding 6e-8 of up to ~60 m, plus the back-projection.
constexpr double kBoxMarginM = 0.002;  // 2 mm
constexpr int kMinPixelsPerObject = 10;

TEST(GroundTruthTest, BoxesContainTheRenderedPointsOfTheirObjects) {
  // Frames in the approach, the turn and the entry.
  for (int first : {20, 80, 120}) {
    SimSource source(SimParams::FromUri(drivers::Uri::Parse(
        "sim://parking?seed=2&frames=1&scale=0.5&depth=1&aa=1&first=" + std::to_string(first))));
    ASSERT_TRUE(source.Next().has_value());
    const GroundTruth& truth = source.ground_truth();
    std::map<int, int> pixels_per_object;
    int outside = 0, ground_off_plane = 0;
    for (std::size_t r = 0; r < source.calibration()->rigs.size(); ++r) {
      const auto& rig = source.calibration()->rigs[r];
      const GtDepth& d = source.depth()[r];
      for (int side = 0; side < 2; ++side) {
        const auto& cam = side == 0 ? rig.left : rig.right;
        Eigen::Isometry3d T_rig_cam = Eigen::Isometry3d::Identity();
        if (side == 1) {
          Eigen::Isometry3d T_right_left = Eigen::Isometry3d::Identity();
          T_right_left.linear() = rig.R;
          T_right_left.translation() = rig.T;
          T_rig_cam = T_right_left.inverse();
        }
        const Eigen::Isometry3d T_world_cam = truth.T_world_vehicle * rig.T_vehicle_rig * T_rig_cam;
        const auto& depth = side == 0 ? d.left_depth_m : d.right_depth_m;
        const auto& ids = side == 0 ? d.left_object_id : d.right_object_id;
        // Every second pixel, its ray from OpenCV's own undistortion (independent of the renderer).
        std::vector<cv::Point2d> px, rays;
        for (int y = 0; y < d.height; y += 2) {
          for (int x = 0; x < d.width; x += 2) px.emplace_back(x, y);
        }
        cv::Mat K(3, 3, CV_64F), D(1, static_cast<int>(cam.distortion.size()), CV_64F);
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) K.at<double>(a, b) = cam.K(a, b);
        }
        for (std::size_t k = 0; k < cam.distortion.size(); ++k) D.at<double>(0, static_cast<int>(k)) = cam.distortion[k];
        cv::undistortPoints(px, rays, K, cam.distortion.empty() ? cv::Mat() : D, cv::noArray(),
                            cv::noArray(),
                            cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
        for (std::size_t k = 0; k < px.size(); ++k) {
          {
            const int x = static_cast<int>(px[k].x), y = static_cast<int>(px[k].y);
            const std::size_t i = static_cast<std::size_t>(y) * d.width + x;
            const double xn = rays[k].x, yn = rays[k].y;
            if (ids[i] == kNoHitId) continue;
            const double z = depth[i];
            const Eigen::Vector3d p = T_world_cam * Eigen::Vector3d(xn * z, yn * z, z);
            if (ids[i] == kGroundId) {
              if (std::abs(p.z()) > 0.02) ++ground_off_plane;
              continue;
            }
            const GtBox* box = truth.Find(ids[i]);
            ASSERT_NE(box, nullptr) << "pixel labelled with unknown id " << ids[i];
            ++pixels_per_object[ids[i]];
            if (!box->Contains(p, kBoxMarginM)) ++outside;
          }
        }
      }
    }
    EXPECT_EQ(outside, 0) << "frame " << first;
    EXPECT_EQ(ground_off_plane, 0) << "frame " << first;
    int cars = 0, pedestrians = 0;
    for (const auto& [id, n] : pixels_per_object) {
      if (n < kMinPixelsPerObject) continue;
      const std::string& c = truth.Find(id)->class_name;
      cars += c == "car";
      pedestrians += c == "pedestrian";
    }
    EXPECT_GE(cars, 3) << "frame " << first;
    EXPECT_GE(pedestrians, 1) << "frame " << first;
  }
}

TEST(GroundTruthTest, SurvivesLcmEncoding) {
  SimSource source(SimParams::FromUri(drivers::Uri::Parse("sim://parking?seed=9&frames=200")));
  const GroundTruth t = source.TruthAt(77);
  const auto bytes = Encode(t);
  const GroundTruth u = DecodeGroundTruth(bytes.data(), bytes.size(), "test");
  EXPECT_EQ(u.stamp_ns, t.stamp_ns);
  EXPECT_EQ(u.sequence, 77u);
  EXPECT_EQ(u.seed, 9u);
  EXPECT_EQ(u.ego_phase, t.ego_phase);
  EXPECT_TRUE(u.T_world_vehicle.isApprox(t.T_world_vehicle, 1e-12));
  ASSERT_EQ(u.objects.size(), t.objects.size());
  for (std::size_t i = 0; i < t.objects.size(); ++i) {
    EXPECT_EQ(u.objects[i].id, t.objects[i].id);
    EXPECT_EQ(u.objects[i].class_name, t.objects[i].class_name);
    EXPECT_EQ(u.objects[i].center_m, t.objects[i].center_m);
    EXPECT_EQ(u.objects[i].velocity_mps, t.objects[i].velocity_mps);
  }
  ASSERT_EQ(u.bays.size(), t.bays.size());
  EXPECT_EQ(u.bays[0].feasible, t.bays[0].feasible);
  EXPECT_THROW(DecodeGroundTruth(bytes.data(), bytes.size() / 2, "cut.lcmlog"), romo::Error);
  try {
    DecodeGroundTruth(bytes.data(), 3, "cut.lcmlog");
    FAIL();
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("cut.lcmlog"), std::string::npos) << e.what();
  }
}

TEST(GroundTruthTest, GnssFixFollowsTheGeodeticOrigin) {
  constexpr double kRoundTripTolM = 1e-6;  // GeographicLib round trip is exact to ~nm
  SimSource source(SimParams::FromUri(drivers::Uri::Parse("sim://parking?frames=200")));
  const GeographicLib::LocalCartesian lc(48.0833, 11.2791, 600.0);
  for (std::uint64_t i : {0u, 60u, 149u}) {
    const GroundTruth t = source.TruthAt(i);
    EXPECT_DOUBLE_EQ(t.origin.latitude_deg, 48.0833);
    double e, n, u;
    lc.Forward(t.gnss.latitude_deg, t.gnss.longitude_deg, t.gnss.altitude_m, e, n, u);
    EXPECT_NEAR(e, t.T_world_vehicle.translation().x(), kRoundTripTolM);
    EXPECT_NEAR(n, t.T_world_vehicle.translation().y(), kRoundTripTolM);
    EXPECT_NEAR(u, t.T_world_vehicle.translation().z(), kRoundTripTolM);
  }
}

TEST(GroundTruthTest, CorruptCountsAreRejectedBeforeAllocating) {
  // No objects and no bays: the message ends with num_objects = 0 and num_bays = 0.
  GroundTruth truth;
  truth.scene = "parking";
  std::vector<std::uint8_t> bytes = Encode(truth);
  ASSERT_GE(bytes.size(), 8u);
  const std::size_t num_objects_at = bytes.size() - 8;
  // 2^31 - 1 objects would make LCM's decoder allocate ~400 GB for a ~300-byte message.
  bytes[num_objects_at] = 0x7f;
  bytes[num_objects_at + 1] = bytes[num_objects_at + 2] = bytes[num_objects_at + 3] = 0xff;
  try {
    DecodeGroundTruth(bytes.data(), bytes.size(), "gt");
    FAIL() << "a corrupt object count was accepted";
  } catch (const romo::Error& e) {
    EXPECT_NE(std::string(e.what()).find("gt: romo_lcm.ground_truth_t.num_objects = 2147483647 does not fit"),
              std::string::npos)
        << e.what();
  }
  // -1: the generated decoder would throw std::length_error instead of romo::Error.
  bytes[num_objects_at] = 0xff;
  EXPECT_THROW(DecodeGroundTruth(bytes.data(), bytes.size(), "gt"), romo::Error);
  GtDepth depth;
  depth.width = depth.height = 0;
  std::vector<std::uint8_t> depth_bytes = Encode(depth);
  depth_bytes[depth_bytes.size() - 1] = 100;  // size = 100 pixels in a message that holds none
  EXPECT_THROW(DecodeGtDepth(depth_bytes.data(), depth_bytes.size(), "gt"), romo::Error);
}

}  // namespace
}  // namespace romo::sim
