#pragma once
/// Rectification of one rig: maps computed once from the calibration (cv::stereoRectify +
/// cv::initUndistortRectifyMap), applied per frame, with the rectified geometry for reprojection.
#include <memory>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "romo/drivers/calibration.hpp"

namespace romo::stereo {

/// Pinhole geometry of a rectified pair (both cameras share it; CALIB_ZERO_DISPARITY).
struct RectifiedGeometry {
  double focal_px = 0.0;  ///< f of eq. 2.1-2.3
  double cx_px = 0.0;
  double cy_px = 0.0;
  double baseline_m = 0.0;  ///< b of eq. 2.1-2.3
  /// Rotation from the rectified left frame into the rig frame (= left optical frame): the
  /// transpose of stereoRectify's R1. Identity for an ideally mounted rig.
  Eigen::Matrix3d R_rig_rect = Eigen::Matrix3d::Identity();
};

class Rectifier {
 public:
  /// @throws romo::Error naming the rig and the reason when the calibration cannot be rectified
  ///         into a horizontal pair (no baseline, vertical or swapped cameras, cameras rotated
  ///         too far apart, non-finite or non-positive intrinsics, no common field of view).
  explicit Rectifier(const drivers::RigCalibration& rig);
  ~Rectifier();
  Rectifier(Rectifier&&) noexcept;
  Rectifier& operator=(Rectifier&&) noexcept;

  /// Remaps a raw pair into the rectified pair (bilinear). Both images must have the
  /// calibration's size and the same type.
  /// @throws romo::Error naming the size that disagrees.
  void Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_rect, cv::Mat* right_rect) const;

  const RectifiedGeometry& geometry() const;
  /// OpenCV's 4x4 disparity-to-depth matrix (cv::reprojectImageTo3D).
  const cv::Mat& Q() const;
  int width() const;
  int height() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace romo::stereo
