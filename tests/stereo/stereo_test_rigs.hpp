#pragma once
// Rig calibrations built in code for the stereo tests (the shared RoMo contract: 400 px focal,
// 0.25 m baseline, small distortion, right camera at +x).
#include <cmath>
#include <string>

#include "romo/drivers/calibration.hpp"

namespace romo::stereo::testing {

inline drivers::RigCalibration MakeRig(int rig_id, int width, int height, bool distortion = true) {
  drivers::RigCalibration rig;
  rig.rig_id = rig_id;
  rig.name = "test" + std::to_string(rig_id);
  rig.width_px = width;
  rig.height_px = height;
  for (drivers::CameraIntrinsics* cam : {&rig.left, &rig.right}) {
    cam->K << 400.0, 0.0, (width - 1) / 2.0, 0.0, 400.0, (height - 1) / 2.0, 0.0, 0.0, 1.0;
    if (distortion) cam->distortion = {-0.02, 0.004, 0.0, 0.0, 0.0};
  }
  rig.T = Eigen::Vector3d(-0.25, 0.0, 0.0);
  // Front rig of the sample vehicle: 1.2 m high at x = 1.4 m, pitched down 15 degrees.
  const double pitch = 15.0 * M_PI / 180.0;
  Eigen::Matrix3d R_vehicle_cam;  // optical (x right, y down, z fwd) -> vehicle (x fwd, y left, z up)
  R_vehicle_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  rig.T_vehicle_rig.linear() = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).toRotationMatrix() * R_vehicle_cam;
  rig.T_vehicle_rig.translation() = Eigen::Vector3d(1.4, 0.0, 1.2);
  return rig;
}

}  // namespace romo::stereo::testing
