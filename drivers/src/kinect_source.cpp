// kinect://<index>: a Kinect v1 through libfreenect (RGB 640x480 + 11-bit depth).
// Recorded sessions replay through the same code with fakenect:
//   fakenect DUMPDIR romo record --source kinect://0 --out session.lcmlog --frames N
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>
#include <vector>

#include <libfreenect.h>

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

// libfreenect's sync wrapper waits for the next frame without a timeout (forever once frames stop:
// a device unplugged, a fakenect dump played to its end) and frees its buffers on its own thread
// when the stream ends, while a reader may still be copying the last frame. The source runs the
// event loop itself instead: frames are copied into its own buffers under its own lock, and a
// stream that delivers nothing for the timeout ends, reported.
constexpr std::chrono::seconds kFrameTimeout{2};        // the device delivers 30 frames per second
constexpr std::chrono::seconds kFirstFrameTimeout{10};  // starting it takes a few seconds

class KinectSource : public FrameSource {
 public:
  explicit KinectSource(int index) : index_(index), calibration_(DefaultKinectCalibration(index)) {
    counters_.camera_id = "kinect:" + std::to_string(index);
    if (freenect_init(&context_, nullptr) < 0 || context_ == nullptr) {
      Fail("kinect " + std::to_string(index) + ": libfreenect could not start");
    }
    if (freenect_open_device(context_, &device_, index) < 0 || device_ == nullptr) {
      freenect_shutdown(context_);
      Fail("kinect " + std::to_string(index) + ": the device could not be opened (in use by another program?)");
    }
    freenect_set_user(device_, this);
    freenect_set_video_mode(device_, freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB));
    freenect_set_depth_mode(device_, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT));
    video_buffer_.resize(static_cast<std::size_t>(kWidth) * kHeight * 3);
    depth_buffer_.resize(static_cast<std::size_t>(kWidth) * kHeight);
    freenect_set_video_buffer(device_, video_buffer_.data());
    freenect_set_depth_buffer(device_, depth_buffer_.data());
    freenect_set_video_callback(device_, &KinectSource::OnVideo);
    freenect_set_depth_callback(device_, &KinectSource::OnDepth);
    freenect_start_video(device_);
    freenect_start_depth(device_);
    events_thread_ = std::thread([this] { RunEvents(); });
  }

  ~KinectSource() override {
    stop_ = true;
    events_thread_.join();
    freenect_stop_depth(device_);
    freenect_stop_video(device_);
    freenect_close_device(device_);
    freenect_shutdown(context_);
  }

  std::optional<FrameSet> Next() override {
    const auto timeout = counters_.completed == 0 ? kFirstFrameTimeout : kFrameTimeout;
    std::unique_lock<std::mutex> lock(mutex_);
    frame_ready_.wait_for(lock, timeout, [this] { return (new_rgb_ && new_depth_) || ended_; });
    if (!(new_rgb_ && new_depth_)) {
      // An unplugged device or the end of a fakenect replay: the stream ends, reported.
      if (events_.empty()) {
        events_.push_back("kinect " + std::to_string(index_) + " stopped after " + std::to_string(counters_.completed) +
                          " frames: " +
                          (ended_ ? std::string("its event loop ended (unplugged, or the end of a fakenect dump)")
                                  : "no frame for " + std::to_string(timeout.count()) + " s (unplugged or hung)"));
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
    std::memcpy(frame.rgb.data.data(), latest_rgb_.data(), frame.rgb.data.size());
    frame.depth = Image::Allocate(PixelFormat::kMono16, kWidth, kHeight);
    const auto& table = RawToMillimetres();
    auto* mm = reinterpret_cast<std::uint16_t*>(frame.depth.data.data());
    for (int i = 0; i < kWidth * kHeight; ++i) mm[i] = table[latest_depth_[static_cast<std::size_t>(i)] & 0x07FF];
    new_rgb_ = new_depth_ = false;
    lock.unlock();
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
  void RunEvents() {
    while (!stop_) {
      timeval tv{0, 100000};
      if (freenect_process_events_timeout(context_, &tv) < 0) break;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ended_ = true;
    frame_ready_.notify_all();
  }

  static void OnVideo(freenect_device* device, void* rgb, std::uint32_t) {
    auto* self = static_cast<KinectSource*>(freenect_get_user(device));
    self->Keep(static_cast<const std::uint8_t*>(rgb), self->video_buffer_.size(), &self->latest_rgb_, &self->new_rgb_);
  }
  static void OnDepth(freenect_device* device, void* depth, std::uint32_t) {
    auto* self = static_cast<KinectSource*>(freenect_get_user(device));
    self->Keep(static_cast<const std::uint16_t*>(depth), self->depth_buffer_.size(), &self->latest_depth_,
               &self->new_depth_);
  }
  // A frame from libfreenect's thread: copied out of its buffer before the next one overwrites it.
  template <typename T>
  void Keep(const T* data, std::size_t count, std::vector<T>* latest, bool* fresh) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest->assign(data, data + count);
    *fresh = true;
    frame_ready_.notify_all();
  }

  int index_;
  Calibration calibration_;
  CameraCounters counters_;
  std::vector<std::string> events_;
  freenect_context* context_ = nullptr;
  freenect_device* device_ = nullptr;
  std::vector<std::uint8_t> video_buffer_;   // libfreenect writes frames here
  std::vector<std::uint16_t> depth_buffer_;
  std::mutex mutex_;  // guards the latest frames and the flags below
  std::condition_variable frame_ready_;
  std::vector<std::uint8_t> latest_rgb_;
  std::vector<std::uint16_t> latest_depth_;
  bool new_rgb_ = false, new_depth_ = false, ended_ = false;
  std::atomic<bool> stop_{false};
  std::thread events_thread_;
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
