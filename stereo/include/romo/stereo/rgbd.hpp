#pragma once
/// Kinect-class RGB-D: RGB <-> depth warping by focal-length ratio about the principal points
/// (dissertation eq. 2.4-2.6) and depth-to-cloud with per-point sigma_z (eq. 2.3).
#include <opencv2/core/mat.hpp>

#include "romo/core/point_cloud.hpp"
#include "romo/drivers/frames.hpp"

namespace romo::stereo {

/// Pinhole intrinsics of one Kinect camera, px.
struct PinholeIntrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  /// @throws romo::Error naming @p what and the bad value.
  void Validate(const char* what) const;
};

/// A Kinect v1: IR (depth) and RGB cameras plus the IR projector baseline for eq. 2.3.
/// Defaults are nominal Kinect v1 figures (IR f ~ 580 px, RGB f ~ 525 px, 640x480).
struct KinectModel {
  PinholeIntrinsics ir{580.0, 580.0, 319.5, 239.5};
  PinholeIntrinsics rgb{525.0, 525.0, 319.5, 239.5};
  double projector_baseline_m = 0.075;  ///< b of eq. 2.3 (IR projector to IR camera)
  double sigma_d_px = 0.125;  ///< disparity noise of the structured-light matcher (1/8 px)
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// Eq. 2.4-2.5: the depth image resampled onto the RGB pixel grid (output size = @p rgb_size),
/// nearest neighbour so depth is never blended across edges; 0 where the source falls outside.
/// @param depth CV_16UC1 or CV_32FC1.
cv::Mat WarpDepthToRgb(const cv::Mat& depth, const KinectModel& kinect, cv::Size rgb_size);

/// Eq. 2.6: the RGB (or grey) image resampled onto the depth pixel grid (output size =
/// @p depth_size), bilinear; black where the source falls outside.
cv::Mat WarpRgbToDepth(const cv::Mat& rgb, const KinectModel& kinect, cv::Size depth_size);

/// Points of every pixel with depth in (0, max_range_m] in the IR camera frame (x right, y down,
/// z forward), grey intensity from the RGB image warped onto the depth grid (eq. 2.6), and
/// sigma_z = Z^2 / (b f_ir) * sigma_d (eq. 2.3).
/// @throws romo::Error for an inconsistent frame (depth not mono16, sizes, scale <= 0).
PointCloud DepthToCloud(const drivers::RgbdFrame& frame, const KinectModel& kinect, double max_range_m = 10.0);

}  // namespace romo::stereo
