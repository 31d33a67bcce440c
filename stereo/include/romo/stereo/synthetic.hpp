#pragma once
/// Rectified stereo pairs of a textured plane with exact ground truth, for tests and benchmarks.
#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "romo/stereo/rectification.hpp"

namespace romo::stereo {

struct SyntheticPair {
  cv::Mat left, right;  ///< CV_8UC1 rectified pair
  cv::Mat disparity_px;  ///< CV_32FC1 true disparity of every left pixel
};

/// Renders the plane n . X = distance_m (rectified left frame; n points away from the camera,
/// n_z > 0 for a plane ahead; normalised here) as
/// a rectified pair. The texture is smooth random noise painted onto the plane from the left
/// camera, so the right view is the exact plane-induced warp of the left one.
/// @throws romo::Error when the plane is not in front of the camera at every pixel.
SyntheticPair RenderPlanePair(const RectifiedGeometry& geometry, int width, int height,
                              const Eigen::Vector3d& normal, double distance_m, std::uint32_t seed);

}  // namespace romo::stereo
