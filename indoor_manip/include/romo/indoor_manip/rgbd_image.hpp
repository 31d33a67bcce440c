#pragma once
/// RGB-D frames as OpenCV images with metric depth, and the pinhole model of the depth camera.
#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/frames.hpp"

namespace romo::indoor_manip {

/// Pinhole intrinsics of the depth camera (RGB is assumed registered to depth).
struct DepthIntrinsics {
  double fx_px = 0.0;
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;

  /// @throws romo::Error naming the field and value when a focal length is not positive.
  void Validate() const;
  Eigen::Vector3d Unproject(double u_px, double v_px, double z_m) const {
    return {(u_px - cx_px) * z_m / fx_px, (v_px - cy_px) * z_m / fy_px, z_m};
  }
  Eigen::Vector2d Project(const Eigen::Vector3d& p) const {
    return {fx_px * p.x() / p.z() + cx_px, fy_px * p.y() / p.z() + cy_px};
  }
  /// Parses "fx,fy,cx,cy"; @throws romo::Error naming @p what and the text.
  static DepthIntrinsics Parse(const std::string& text, const std::string& what);
};

/// The depth intrinsics a source carries (its first rig's left camera), or nullopt.
std::optional<DepthIntrinsics> IntrinsicsFromSource(const drivers::FrameSource& source);

/// One RGB-D frame: rgb CV_8UC3 (RGB order), gray CV_8UC1, depth_m CV_32FC1 (0 = no depth).
struct RgbdImage {
  cv::Mat rgb;
  cv::Mat gray;
  cv::Mat depth_m;
  std::int64_t stamp_ns = 0;

  int width() const { return depth_m.cols; }
  int height() const { return depth_m.rows; }
};

/// Converts and validates a driver frame.
/// @throws romo::Error naming @p origin when RGB and depth differ in size, the depth is not
/// mono16, the RGB is not rgb8/mono8, or no pixel has depth.
RgbdImage ToRgbdImage(const drivers::RgbdFrame& frame, const std::string& origin);

}  // namespace romo::indoor_manip
