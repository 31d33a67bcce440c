#pragma once
/// Simulator ground truth: what the scene really contains at each frame. Recorded on its own
/// LCM channels (never read by the perception pipeline) and decoded here for evaluation
/// (`romo eval scene`) and tests. World frame: local ENU (x east, y north, z up) around origin.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/drivers/frames.hpp"

namespace romo::sim {

/// Channel of GroundTruth messages (romo_lcm.ground_truth_t), one per frame.
inline constexpr const char* kGroundTruthChannel = "ROMO_GT_FRAME";
/// Channel of a rig's per-pixel truth (romo_lcm.gt_depth_t): "ROMO_GT_DEPTH_RIG<k>".
std::string DepthChannel(int rig_id);

/// An upright box on the ground plane (only yaw free), in the world frame.
struct GtBox {
  int id = 0;                  ///< unique per scene, > 0; also the object id in depth truth
  std::string class_name;      ///< "car", "pedestrian", "curb", "wall"
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< centre; z = height / 2
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();    ///< length (box x), width (box y), height
  double yaw_rad = 0.0;        ///< rotation of the box x axis about world z
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();

  /// True when world point @p p_world lies inside the box grown by @p margin_m on every side.
  bool Contains(const Eigen::Vector3d& p_world, double margin_m = 0.0) const;
  /// The 4 ground corners (x, y) counter-clockwise.
  std::vector<Eigen::Vector2d> Footprint() const;
};

/// True when the footprints of @p a and @p b overlap (separating-axis test on the ground plane;
/// heights are ignored: everything stands on the ground).
bool FootprintsOverlap(const GtBox& a, const GtBox& b);

/// A free parking bay between two parked cars.
struct GtBay {
  int id = 0;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  ///< on the ground (z = 0)
  double width_m = 0.0;   ///< free width along the row, between the two neighbours' boxes
  double depth_m = 0.0;   ///< extent into the row (perpendicular to it)
  double yaw_rad = 0.0;   ///< direction of the row (the bay's width axis) about world z
  bool feasible = false;  ///< wide enough for the ego vehicle with the required side margins
  int left_car_id = 0;    ///< neighbour at the bay's -width side
  int right_car_id = 0;   ///< neighbour at the bay's +width side

  /// The bay as a box of height @p height_m (for overlap tests).
  GtBox AsBox(double height_m) const;
};

/// The fixed geodetic origin of the world frame (WGS84).
struct GeodeticOrigin {
  double latitude_deg = 48.0833;
  double longitude_deg = 11.2791;
  double altitude_m = 600.0;
};

/// Everything true about one frame.
struct GroundTruth {
  std::int64_t stamp_ns = 0;
  std::uint64_t sequence = 0;
  std::string scene;
  std::uint64_t seed = 0;
  GeodeticOrigin origin;
  Eigen::Isometry3d T_world_vehicle = Eigen::Isometry3d::Identity();
  double ego_speed_mps = 0.0;
  double ego_yaw_rate_radps = 0.0;
  Eigen::Vector3d ego_size_m = Eigen::Vector3d(2.8, 1.6, 1.9);  ///< length, width, height
  std::string ego_phase;  ///< "approach", "turn", "entry", "parked" (or "wait" between them)
  drivers::GnssFix gnss;  ///< exact fix of the vehicle origin via the geodetic origin
  std::vector<GtBox> objects;
  std::vector<GtBay> bays;

  /// The object with @p id, or nullptr.
  const GtBox* Find(int id) const;
};

/// Per-pixel truth of one rig (pixel centres of the delivered images).
struct GtDepth {
  std::int64_t stamp_ns = 0;
  std::uint64_t sequence = 0;
  int rig_id = 0;
  int width = 0;
  int height = 0;
  std::vector<float> left_depth_m;   ///< z in the left camera frame; 0 = no hit
  std::vector<float> right_depth_m;  ///< z in the right camera frame; 0 = no hit
  std::vector<std::int16_t> left_object_id;   ///< GtBox::id, 0 = ground, -1 = nothing
  std::vector<std::int16_t> right_object_id;
};

/// Object id of ground pixels and of pixels whose ray hits nothing.
inline constexpr int kGroundId = 0;
inline constexpr int kNoHitId = -1;

/// Disparity (px) that depth @p depth_m has for focal length @p fx_px and @p baseline_m; 0 for
/// no depth. Eq. 2.1 inverted: d = b f / z.
inline float DisparityFromDepth(float depth_m, double fx_px, double baseline_m) {
  return depth_m > 0.f ? static_cast<float>(fx_px * baseline_m / depth_m) : 0.f;
}

std::vector<std::uint8_t> Encode(const GroundTruth& truth);
std::vector<std::uint8_t> Encode(const GtDepth& depth);
/// @throws romo::Error naming @p origin when the bytes are not a valid message.
GroundTruth DecodeGroundTruth(const void* data, std::size_t size, const std::string& origin);
GtDepth DecodeGtDepth(const void* data, std::size_t size, const std::string& origin);

}  // namespace romo::sim
