#pragma once
/// Hand rotation from dense Farneback flow inside the hand mask lifted to 3D (Sec. 4.2.4,
/// eqs. 4.1-4.3): per-axis angles in the hand frame {H} whose z axis is the plane normal.
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "romo/indoor_manip/rgbd_image.hpp"

namespace romo::indoor_manip {

struct RotationParams {
  /// Flow vectors whose end point depth differs from the start's by more than this are outliers
  /// before fitting (metres).
  double max_depth_change_m = 0.04;
  /// Flow vectors used at most (subsampled on a grid) per step.
  int max_vectors = 600;
  int min_vectors = 12;
  /// Residual gate after the first fit: inliers within this factor of the median residual.
  double inlier_factor = 2.5;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

struct RotationStep {
  bool valid = false;
  Eigen::Vector3d angle_rad = Eigen::Vector3d::Zero();  ///< about H x, y, z
  int vectors = 0;
  int inliers = 0;
};

/// Rotation between frames k and k+1 of the hand masked by @p mask_prev.
/// @param R_camera_hand columns = hand frame axes in camera coordinates.
RotationStep EstimateHandRotation(const RgbdImage& prev, const RgbdImage& next,
                                  const cv::Mat& mask_prev, const cv::Rect& bbox_prev,
                                  const DepthIntrinsics& intrinsics,
                                  const Eigen::Matrix3d& R_camera_hand,
                                  const RotationParams& params);

/// 2D rigid fit (rotation + translation) of @p to onto @p from; returns the angle (radians).
/// Points are 2 x N. Used per hand-frame plane (eq. 4.1) and exposed for tests.
double FitPlanarRotation(const Eigen::Matrix2Xd& from, const Eigen::Matrix2Xd& to);

struct AngleHistogram {
  double min_deg = 0.0;
  double bin_deg = 1.0;
  std::vector<int> counts;
};
/// Histogram of @p values_deg over [min_deg, max_deg) with @p bins bins (values outside clamp).
AngleHistogram MakeHistogram(const std::vector<double>& values_deg, double min_deg,
                             double max_deg, int bins);

}  // namespace romo::indoor_manip
