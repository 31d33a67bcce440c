#pragma once
/// Disparity to 3D points (eq. 2.2) with per-point depth uncertainty sigma_z = Z^2/(b f) sigma_d
/// (eq. 2.3), transformed into the caller's frame.
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "romo/core/point_cloud.hpp"
#include "romo/stereo/rectification.hpp"

namespace romo::stereo {

struct ReprojectionParams {
  /// Disparity standard deviation of the matcher, px (eq. 2.3). SGM with subpixel refinement is
  /// typically good to a quarter pixel on textured surfaces.
  double sigma_d_px = 0.25;
  /// Points farther than this from the rig origin are dropped, m.
  double max_range_m = 40.0;
  /// Pixels whose 3x3 neighbourhood's valid disparities span more than this fraction of their
  /// own, and more than min_outline_step_px, are dropped (0 keeps all). Matching windows smear
  /// disparity across an object's outline, and those in-between points would bridge objects that
  /// stand close behind one another; a surface is only cut where it is seen within a few degrees
  /// of grazing.
  double max_disparity_spread = 0.0;
  /// The floor under that spread, px: far away a fraction of the disparity is within the
  /// matcher's noise (3x3 of sigma_d spans about 3 sigma_d).
  double min_outline_step_px = 1.0;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// Reprojects every valid pixel of @p disparity (output of StereoSgm::execute: CV_16SC1 or
/// CV_8UC1, value = disparity x @p subpixel_scale, @p invalid_disparity = no match) into
/// @p T_out_rig * (rig frame point). Pixels with invalid or non-positive disparity or beyond
/// max_range_m are dropped. Intensity comes from @p intensity (CV_8UC1 rectified left image,
/// optional: 0 when empty). Points are in row-major pixel order.
/// @throws romo::Error when sizes or types disagree.
PointCloud ReprojectDisparity(const cv::Mat& disparity, int subpixel_scale, int invalid_disparity,
                              const cv::Mat& intensity, const RectifiedGeometry& geometry,
                              const ReprojectionParams& params,
                              const Eigen::Isometry3d& T_out_rig = Eigen::Isometry3d::Identity());

}  // namespace romo::stereo
