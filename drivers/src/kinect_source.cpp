// kinect://<index>: a Kinect v1 through libfreenect's sync API (RGB 640x480 + 11-bit depth).
// Recorded sessions replay through the same code with fakenect:
//   fakenect DUMPDIR romo record --source kinect://0 --out session.lcmlog --frames N
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include <libfreenect.h>
#include <libfreenect_sync.h>

#include "romo/core/check.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frame_source.hpp"

namespace romo::drivers {
namespace {

constexpr int kWidth = 640;   // FREENECT_RESOLUTION_MEDIUM, the only mode fakenect replays
constexpr int kHeight = 480;
constexpr int kInvalidRaw = 2047;  // 11-bit depth: no return

// Default Kinect v1 intrinsics at 640x480: fx = fy = 525, cx = 319.5, cy = 239.5 px, the values
// ROS's openni/freenect camera drivers publish for an uncalibrated Kinect and that the TUM RGB-D
// benchmark lists as the "ROS default" (vision.in.tum.de/data/datasets/rgbd-dataset/file_formats).
// They describe the RGB camera; the unregistered depth camera is within a few per cent (TUM's own
// calibrations: fx 517-591). romo manip --intrinsics overrides them with a calibrated K.
constexpr double kDefaultFocalPx = 525.0;
constexpr double kDefaultCxPx = 319.5;
constexpr double kDefaultCyPx = 239.5;
Calibration DefaultKinectCalibration(int index) {
  Eigen::Matrix3d K;
  K << kDefaultFocalPx, 0, kDefaultCxPx, 0, kDefaultFocalPx, kDefaultCyPx, 0, 0, 1;
  Calibration c;
  c.rigs.push_back(RgbdSensorRig("kinect" + std::to_string(index), kWidth, kHeight, K));
  return c;
}

// Raw 11-bit Kinect disparity to millimetres (the OpenKinect community's tangent fit,
// depth_m = 0.1236 * tan(raw / 2842.5 + 1.1863)); 0 where the sensor saw nothing or the fit
// leaves the Kinect's 0.4-10 m working range.
const std::array<std::uint16_t, 2048>& RawToMillimetres() {
  static const std::array<std::uint16_t, 2048> table = [] {
    std::array<std::uint16_t, 2048> t{};
    for (int raw = 0; raw < 2048; ++raw) {
      const double m = 0.1236 * std::tan(raw / 2842.5 + 1.1863);
      t[static_cast<std::size_t>(raw)] =
          raw >= kInvalidRaw || !(m > 0.4 && m < 10.0) ? 0 : static_cast<std::uint16_t>(std::lround(m * 1000.0));
    }
    return t;
  }();
  return table;
}

class KinectSource : public FrameSource {
 public:
  explicit KinectSource(int index) : index_(index), calibration_(DefaultKinectCalibration(index)) {
    counters_.camera_id = "kinect:" + std::to_string(index);
  }
  ~KinectSource() override { freenect_sync_stop(); }

  std::optional<FrameSet> Next() override {
    void* rgb = nullptr;
    void* depth = nullptr;
    std::uint32_t rgb_ts = 0;
    std::uint32_t depth_ts = 0;
    if (freenect_sync_get_video(&rgb, &rgb_ts, index_, FREENECT_VIDEO_RGB) != 0 ||
        freenect_sync_get_depth(&depth, &depth_ts, index_, FREENECT_DEPTH_11BIT) != 0) {
      // An unplugged device or the end of a fakenect replay: the stream ends, reported.
      if (events_.empty()) {
        events_.push_back("kinect " + std::to_string(index_) + " stopped delivering frames after " +
                          std::to_string(counters_.completed));
      }
      return std::nullopt;
    }
    FrameSet set;
    set.sequence = counters_.completed;
    // The device clock is 32-bit and free-running; the host clock orders frames across sources.
    set.stamp_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::system_clock::now().time_since_epoch())
                       .count();
    RgbdFrame frame;
    frame.rgb = Image::Allocate(PixelFormat::kRgb8, kWidth, kHeight);
    std::memcpy(frame.rgb.data.data(), rgb, frame.rgb.data.size());
    frame.depth = Image::Allocate(PixelFormat::kMono16, kWidth, kHeight);
    const auto& table = RawToMillimetres();
    const auto* raw = static_cast<const std::uint16_t*>(depth);
    auto* mm = reinterpret_cast<std::uint16_t*>(frame.depth.data.data());
    for (int i = 0; i < kWidth * kHeight; ++i) mm[i] = table[raw[i] & 0x07FF];
    frame.depth_scale_m = 0.001;
    frame.stamp_ns = set.stamp_ns;
    frame.sequence = set.sequence;
    set.rgbd = std::move(frame);
    ++counters_.completed;
    return set;
  }

  SourceStatus status() const override {
    SourceStatus status;
    status.cameras.push_back(counters_);
    status.events = events_;
    return status;
  }

  /// The Kinect v1 defaults (see kDefaultFocalPx): libfreenect reads no calibration.
  const Calibration* calibration() const override { return &calibration_; }

 private:
  int index_;
  Calibration calibration_;
  CameraCounters counters_;
  std::vector<std::string> events_;
};

}  // namespace

std::unique_ptr<FrameSource> OpenKinectSource(const Uri& uri) {
  if (!uri.query.empty()) Fail(uri.ToString() + ": kinect:// takes no options");
  char* end = nullptr;
  const long index = std::strtol(uri.path.c_str(), &end, 10);
  if (uri.path.empty() || *end != '\0' || index < 0 || index > 63) {
    Fail(uri.ToString() + ": Kinect index '" + uri.path + "' must be a number 0-63 (kinect://0)");
  }
  // Count devices first: the sync API would only fail later with a generic code.
  freenect_context* context = nullptr;
  int devices = 0;
  if (freenect_init(&context, nullptr) >= 0 && context != nullptr) {
    devices = freenect_num_devices(context);
    freenect_shutdown(context);
  }
  if (devices <= index) {
    Fail("no Kinect found at index " + std::to_string(index) + " (" + std::to_string(std::max(devices, 0)) +
         " attached; for a recorded session run under fakenect DUMPDIR)");
  }
  return std::make_unique<KinectSource>(static_cast<int>(index));
}

}  // namespace romo::drivers
