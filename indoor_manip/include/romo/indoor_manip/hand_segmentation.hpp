#pragma once
/// Hand blob by breadth-first region growing over pixels with valid depth (Sec. 4.2.3).
#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "romo/indoor_manip/interaction_plane.hpp"
#include "romo/indoor_manip/rgbd_image.hpp"

namespace romo::indoor_manip {

struct HandSegmentationParams {
  /// Two 4-neighbour pixels join when their 3D points are closer than this (metres).
  double max_neighbour_distance_m = 0.02;
  /// Pixels closer than this to the interaction plane are background (metres).
  double plane_margin_m = 0.015;
  /// Pixels farther than this from the seed point are not hand (metres): stops leaks into an arm.
  double max_radius_m = 0.15;
  int min_pixels = 20;
  /// Radius of the window searched for a depth pixel near a predicted seed (pixels).
  int seed_search_radius_px = 12;

  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

struct HandBlob {
  cv::Mat mask;  ///< CV_8UC1, 255 on hand pixels
  cv::Rect bbox;
  int pixel_count = 0;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();  ///< camera frame
  cv::Point seed;
};

/// Grows the hand region from @p seed. @p plane may be null (no background removal).
/// @throws romo::Error when the seed lies outside the image or has no valid depth.
HandBlob GrowHandRegion(const RgbdImage& image, const DepthIntrinsics& intrinsics,
                        cv::Point seed, const InteractionPlane* plane,
                        const HandSegmentationParams& params);

/// Tracking variant: picks a seed near the predicted 3D position (the valid-depth pixel in a
/// window around its projection whose point is closest to it) and grows from there; nullopt when
/// nothing within max_radius_m or fewer than min_pixels pixels were found.
std::optional<HandBlob> FindHandNear(const RgbdImage& image, const DepthIntrinsics& intrinsics,
                                     const Eigen::Vector3d& predicted_m,
                                     const InteractionPlane* plane,
                                     const HandSegmentationParams& params);

}  // namespace romo::indoor_manip
