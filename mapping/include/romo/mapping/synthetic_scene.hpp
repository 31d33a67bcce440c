#pragma once
/// Synthetic scenes with known answers for tests and benchmarks: boxes and cylinders standing on
/// a ground plane (vehicle frame, z up), surfaces sampled uniformly at random with a fixed seed.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "romo/core/point_cloud.hpp"

namespace romo::mapping {

struct SceneObject {
  enum class Shape { kBox, kCylinder };
  Shape shape = Shape::kBox;
  /// Footprint centre on the ground (x, y), metres; the object stands on z = ground height.
  Eigen::Vector2f center_xy = Eigen::Vector2f::Zero();
  /// Box: length (along yaw), width, height. Cylinder: diameter, (ignored), height. Metres.
  Eigen::Vector3f size = Eigen::Vector3f::Ones();
  float yaw_rad = 0.f;
};

struct SyntheticSceneParams {
  /// Mean surface point density, points per square metre.
  float density_per_m2 = 2500.f;
  /// Gaussian noise on every coordinate, metres (sigma).
  float noise_m = 0.f;
  /// Square ground patch half-size, metres; 0 = no ground points.
  float ground_half_extent_m = 0.f;
  float ground_height_m = 0.f;
  /// Object faces on the ground (bottoms) are never sampled, as a camera never sees them.
  std::uint64_t seed = 1;
};

struct SyntheticScene {
  PointCloud cloud;
  /// Per point: index into the objects, or -1 for ground.
  std::vector<int> labels;
  std::vector<SceneObject> objects;
};

/// Samples @p objects (and optionally ground) into one cloud. sigma_z_m is set to noise_m.
SyntheticScene MakeSyntheticScene(const std::vector<SceneObject>& objects,
                                  const SyntheticSceneParams& params);

/// A vehicle-scale parking scene of @p target_points object points at ~450 points/m^2 (a stereo
/// cloud's density at ~10 m): pedestrians on the lane, poles, and as many rows of parked cars
/// (2.6 m bays, some free) as the point count needs; objects at least 0.4 m apart. Optional ground
/// patch (same density, extra points). Deterministic for a given @p seed.
SyntheticScene MakeParkingScene(std::size_t target_points, std::uint64_t seed,
                                float ground_half_extent_m = 0.f);

}  // namespace romo::mapping
