#pragma once
/// Ground removal for the vehicle (dissertation 4.3.2): the terrain is assumed flat and
/// perpendicular to the vehicle's vertical axis (the prior); each frame refines it by RANSAC with
/// the normal constrained around vehicle z; points on or below the plane plus a height tolerance
/// are removed, and those far below it are told apart from the ground (stereo mismatches).
#include <vector>

#include "romo/core/point_cloud.hpp"
#include "romo/mapping/plane_ransac.hpp"

namespace romo::mapping {

struct GroundRemovalParams {
  /// Prior ground height in the vehicle frame (origin is on the ground), metres.
  float prior_height_m = 0.f;
  /// Only points within this band around the prior are RANSAC candidates, metres.
  float search_band_m = 0.3f;
  /// Points up to this height above the fitted plane count as ground (and everything below, down
  /// to the depth below), m.
  float height_tolerance_m = 0.1f;
  /// Points lower under the plane than below_tolerance_m, or below_sigmas times their depth
  /// sigma if more, are removed but are not ground: stereo mismatches seen "through" it. A ground
  /// point's height errs by its depth error times the sine of the sight line's slope, less than
  /// the depth error itself; these lie 0.2-3 m under while true ground at 6 m (sigma 0.12 m)
  /// lies within 0.05 m, and counted as ground they made a parked car beside the vehicle look
  /// gone (simulated scene, seed 3, frame 34). Infinite: all of them are ground.
  float below_tolerance_m = 0.1f;
  float below_sigmas = 1.0f;
  /// RANSAC settings; its axis defaults to vehicle +z and its threshold to 0.05 m.
  PlaneRansacParams ransac = DefaultRansac();
  /// Too few candidates or inliers: keep the prior plane (reported in the result).
  int min_inliers = 50;

  static PlaneRansacParams DefaultRansac();
  /// @throws romo::Error naming the field and value when a field is out of range.
  void Validate() const;
};

struct GroundRemoval {
  Plane plane;                    ///< fitted plane (normal up) or the prior
  bool refined = false;           ///< false: the prior was used
  std::vector<int> ground;        ///< indices on or below plane + tolerance, ascending
  std::vector<int> below;         ///< indices too far below the plane to be ground, ascending
  std::vector<int> obstacles;     ///< the other finite points, ascending
  int ransac_inliers = 0;         ///< inliers of the fitted plane at the RANSAC threshold
  int ransac_iterations = 0;
  std::size_t skipped_non_finite = 0;
};

/// Splits @p cloud (vehicle frame, z up) into ground and obstacles.
/// @throws romo::Error on invalid @p params.
GroundRemoval RemoveGround(const PointCloud& cloud, const GroundRemovalParams& params);

}  // namespace romo::mapping
