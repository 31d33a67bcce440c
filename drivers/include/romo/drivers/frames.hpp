#pragma once
/// Plain frame types shared by every source, the recorder and the pipeline.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace romo::drivers {

enum class PixelFormat : std::uint8_t { kMono8 = 0, kMono16 = 1, kRgb8 = 2 };

/// Bytes per pixel of @p format.
int BytesPerPixel(PixelFormat format);
/// "mono8", "mono16", "rgb8".
const char* ToString(PixelFormat format);

/// A packed image: rows of stride_bytes, the first width * BytesPerPixel bytes of each used.
/// Mono16 samples are native-endian and hold up to 16 significant bits (12-bit cameras: 0-4095).
struct Image {
  PixelFormat format = PixelFormat::kMono8;
  int width = 0;
  int height = 0;
  int stride_bytes = 0;
  std::vector<std::uint8_t> data;

  /// A zero-filled image with stride = width * BytesPerPixel(format).
  static Image Allocate(PixelFormat format, int width, int height);

  bool empty() const { return width == 0 || height == 0; }
  std::uint8_t* row(int y) { return data.data() + static_cast<std::size_t>(y) * stride_bytes; }
  const std::uint8_t* row(int y) const {
    return data.data() + static_cast<std::size_t>(y) * stride_bytes;
  }
  /// Throws romo::Error when sizes and buffer disagree.
  void Validate() const;
};

/// One camera's image with its acquisition metadata.
struct CameraFrame {
  Image image;
  std::int64_t stamp_ns = 0;  ///< hardware (device) timestamp
  std::uint64_t sequence = 0;  ///< camera's frame counter
  std::string camera_id;
};

/// A left/right pair of one rig, paired by device timestamp.
struct StereoFrame {
  int rig_id = 0;
  CameraFrame left;
  CameraFrame right;
  std::int64_t stamp_ns() const { return left.stamp_ns; }
};

/// A Kinect-class frame: colour plus a 16-bit depth image; depth_m = value * depth_scale_m, 0 = none.
struct RgbdFrame {
  Image rgb;
  Image depth;
  double depth_scale_m = 0.001;
  std::int64_t stamp_ns = 0;
  std::uint64_t sequence = 0;
};

/// Vehicle odometry at stamp_ns.
struct VehicleState {
  std::int64_t stamp_ns = 0;
  Eigen::Isometry3d T_world_vehicle = Eigen::Isometry3d::Identity();
  double speed_mps = 0.0;
  double yaw_rate_radps = 0.0;
};

/// A GNSS fix (WGS84).
struct GnssFix {
  std::int64_t stamp_ns = 0;
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double altitude_m = 0.0;
  double horizontal_sigma_m = 0.0;
  bool valid = false;
};

/// Everything a source delivers for one capture instant.
struct FrameSet {
  std::int64_t stamp_ns = 0;
  std::uint64_t sequence = 0;
  std::vector<StereoFrame> stereo;  ///< one per rig that delivered; a missing rig is absent
  std::optional<RgbdFrame> rgbd;
  std::optional<VehicleState> vehicle;
  std::optional<GnssFix> gnss;
};

}  // namespace romo::drivers
