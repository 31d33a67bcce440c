#pragma once
/// Stereo rig calibration: intrinsics, distortion, stereo extrinsics and the rig's pose on the
/// vehicle, stored as OpenCV FileStorage-style YAML (read with yaml-cpp; OpenCV can read the files).
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace romo::drivers {

struct CameraIntrinsics {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  ///< pixels
  std::vector<double> distortion;  ///< OpenCV order k1 k2 p1 p2 [k3 ...]; empty = none
};

struct RigCalibration {
  int rig_id = 0;
  std::string name;  ///< e.g. "front", "left_front"
  int width_px = 0;
  int height_px = 0;
  CameraIntrinsics left;
  CameraIntrinsics right;
  /// Right camera pose: x_right = R * x_left + T (OpenCV stereoCalibrate convention), T in metres.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d T = Eigen::Vector3d::Zero();
  /// Maps points of the rig frame (= left camera frame: x right, y down, z forward) into the
  /// vehicle frame (x forward, y left, z up).
  Eigen::Isometry3d T_vehicle_rig = Eigen::Isometry3d::Identity();

  double baseline_m() const { return T.norm(); }
};

struct Calibration {
  std::vector<RigCalibration> rigs;

  /// The rig with @p rig_id; @throws romo::Error when there is none.
  const RigCalibration& rig(int rig_id) const;

  /// Reads and validates a calibration file (at most 1 MiB).
  /// @throws romo::Error naming file, field and value for anything missing or implausible.
  static Calibration Load(const std::string& path);
  /// Same from YAML text (as carried in recordings); @p origin names it in errors.
  static Calibration FromYaml(const std::string& yaml_text, const std::string& origin);
  /// Validates, then writes ToYaml(); Load of the file gives back identical values.
  void Save(const std::string& path) const;
  /// The %YAML:1.0 / !!opencv-matrix layout, numbers in shortest round-trip form.
  std::string ToYaml() const;
  /// @throws romo::Error naming @p origin, field and value.
  void Validate(const std::string& origin) const;
};

/// An RGB-D sensor (Kinect class) as rig 0 of a calibration: @p K is the depth camera's (the one
/// romo reads); the right camera is the RGB one, a nominal 2.5 cm beside it, which only makes the
/// rig valid for recordings.
RigCalibration RgbdSensorRig(const std::string& name, int width_px, int height_px, const Eigen::Matrix3d& K);

/// Path of the sample RoMo calibration shipped with romo (6 rigs, 782x582), in the source tree
/// or the install tree.
std::string SampleCalibrationPath();

}  // namespace romo::drivers
