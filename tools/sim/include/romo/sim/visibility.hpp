#pragma once
/// How much of a ground-truth object the vehicle's stereo rigs can see: what a detection score
/// should be measured against (an object wholly behind another is not a miss of perception).
#include <vector>

#include <Eigen/Geometry>

#include "romo/drivers/calibration.hpp"
#include "romo/sim/ground_truth.hpp"

namespace romo::sim {

/// Fraction of @p target's surface (its four sides and top, sampled on a grid) seen by some rig of
/// @p calibration with the vehicle at @p T_world_vehicle: of the samples on faces turned towards
/// a rig's left camera, those inside both of that rig's images with no other box of @p scene
/// (cars, pedestrians, curb, hedge; @p target itself is skipped by id) on the way to the left
/// camera. 0 when no face is turned towards any camera.
double VisibleFraction(const GtBox& target, const std::vector<GtBox>& scene,
                       const drivers::Calibration& calibration, const Eigen::Isometry3d& T_world_vehicle);

}  // namespace romo::sim
