#pragma once
/// Supporting planes indoors (Sec. 3.2.3): RANSAC run repeatedly for several planes, or a plane
/// forced through three picked pixels with valid depth.
#include <array>
#include <vector>

#include <Eigen/Core>

#include "romo/mapping/plane_ransac.hpp"

namespace romo::mapping {

struct MultiPlaneParams {
  PlaneRansacParams ransac;
  int max_planes = 4;
  /// A plane with fewer inliers ends the search.
  int min_inliers = 500;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// Fits planes one after another, each on the points the earlier ones left (largest first).
/// @p xyz may hold non-finite points (no depth); they are ignored. Empty when none was found.
std::vector<PlaneFit> FindPlanes(const Eigen::Matrix3Xf& xyz, const MultiPlaneParams& params);

/// The plane through the 3D points of three pixels of an organized cloud (@p xyz has
/// width * height columns, row-major, non-finite = no depth), with its inliers within
/// @p inlier_threshold_m.
/// @throws romo::Error naming the pixel when one lies outside the image or has no depth, or when
/// the three points are (nearly) collinear.
PlaneFit PlaneFromPickedPixels(const Eigen::Matrix3Xf& xyz, int width,
                               const std::array<Eigen::Vector2i, 3>& pixels,
                               float inlier_threshold_m);

}  // namespace romo::mapping
