#pragma once
// Hand motions of the ten actions in plane coordinates (u, v along the plane, h above it).
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace romo::sim_manip::internal {

struct HandPose {
  double u_m = 0.0, v_m = 0.0, h_m = 0.0;
  double yaw_rad = 0.0, pitch_rad = 0.0, roll_rad = 0.0;
};

/// True for the actions performed on a whiteboard (vertical plane facing the camera).
bool IsBoardAction(const std::string& action);
/// @p n poses at @p fps for @p action; the first is at u = v = 0.
std::vector<HandPose> GenerateHandPath(const std::string& action, std::mt19937_64& rng, int n,
                                       double fps);

}  // namespace romo::sim_manip::internal
