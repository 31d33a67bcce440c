#pragma once
/// Runs the manipulation plugin over a frame source: plane choice (RANSAC or three picked
/// pixels), hand seed, every frame, the result. Shared by `romo manip`, `romo eval manip` and tests.
#include <array>
#include <functional>
#include <string>

#include <opencv2/core.hpp>

#include "romo/drivers/frame_source.hpp"
#include "romo/indoor_manip/manip_analyzer.hpp"

namespace romo::indoor_manip {

struct PlaneChoice {
  bool automatic = true;
  std::array<cv::Point, 3> pixels{};
  /// Parses "auto" or "u1,v1,u2,v2,u3,v3"; @throws romo::Error naming the text.
  static PlaneChoice Parse(const std::string& text);
};

/// Parses "u,v"; @throws romo::Error naming @p what and the text.
cv::Point ParsePixel(const std::string& text, const std::string& what);

/// 3 x (w*h) organized cloud of @p image in the camera frame, NaN where there is no depth.
Eigen::Matrix3Xf OrganizedCloud(const RgbdImage& image, const DepthIntrinsics& intrinsics);

/// The interaction plane of @p image: the largest RANSAC plane (automatic) or the plane through
/// the three picked pixels. @throws romo::Error when no plane is found or a pixel has no depth.
InteractionPlane ChooseInteractionPlane(const RgbdImage& image, const DepthIntrinsics& intrinsics,
                                        const PlaneChoice& choice);

struct SessionOptions {
  PlaneChoice plane;
  cv::Point hand_seed;
  /// 0 = all frames.
  int max_frames = 0;
  ManipParams params;
  /// Called after each frame with the number of frames done.
  std::function<void(int)> on_frame;
};

/// Runs everything on @p source. @p intrinsics: the depth camera's.
/// @throws romo::Error for bad frames (sizes, all-zero depth), a seed without depth, no plane.
ManipResult AnalyzeSource(drivers::FrameSource& source, const DepthIntrinsics& intrinsics,
                          const SessionOptions& options, const std::string& origin);

}  // namespace romo::indoor_manip
