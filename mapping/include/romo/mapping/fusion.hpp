#pragma once
/// 360-degree fusion: each rig's cloud (rig frame) into the vehicle frame, compensated for the
/// vehicle's motion between the rigs' capture instants, with overlaps thinned.
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "romo/core/point_cloud.hpp"

namespace romo::mapping {

struct RigCloud {
  int rig_id = 0;
  std::int64_t stamp_ns = 0;                                      ///< capture instant
  Eigen::Isometry3f T_vehicle_rig = Eigen::Isometry3f::Identity();
  PointCloud cloud;                                               ///< rig frame
};

/// Planar vehicle state (constant speed along vehicle x and constant yaw rate over a frame).
struct VehicleMotion {
  float speed_mps = 0.f;
  float yaw_rate_radps = 0.f;
  /// The instant the fused cloud refers to (e.g. the newest rig's stamp).
  std::int64_t reference_stamp_ns = 0;
};

struct FusionParams {
  /// Voxel edge for overlap thinning, metres: in a voxel holding points of several rigs only the
  /// rig with the lowest sigma_z there keeps its points. <= 0 disables thinning.
  float overlap_voxel_m = 0.05f;
  /// Largest |stamp - reference| accepted, seconds (a stale rig is a caller error).
  double max_stamp_offset_s = 1.0;
  void Validate() const;
};

struct FusionStats {
  std::size_t input_points = 0;
  std::size_t skipped_non_finite = 0;
  std::size_t thinned = 0;  ///< overlap points dropped
};

/// Pose of the vehicle at @p stamp_ns in the vehicle frame at motion.reference_stamp_ns
/// (T_ref_then), integrating the constant-turn-rate model exactly.
Eigen::Isometry3f VehicleDisplacement(const VehicleMotion& motion, std::int64_t stamp_ns);

/// Fuses @p rigs into one vehicle-frame cloud at motion.reference_stamp_ns (non-finite points
/// dropped). Points keep their sigma_z and intensity; @p point_rig_ids, when given, receives the
/// rig id each fused point came from (which camera saw it, e.g. to know the viewpoint).
/// @throws romo::Error on invalid params, an inconsistent rig cloud or a stale stamp (names rig).
PointCloud FuseRigClouds(const std::vector<RigCloud>& rigs, const VehicleMotion& motion,
                         const FusionParams& params, FusionStats* stats = nullptr,
                         std::vector<int>* point_rig_ids = nullptr);

}  // namespace romo::mapping
