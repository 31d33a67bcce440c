// The gige:// source over Aravis 0.8: a grab thread and buffer pool per camera, pairing per rig,
// frame sets across rigs, reconnection with back-off. Everything Aravis/GLib lives in this file.
#include <arpa/inet.h>
#include <arv.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"
#include "romo/drivers/gige.hpp"

namespace romo::drivers {
namespace {

using Clock = std::chrono::steady_clock;

// Aravis's device list and discovery are process-wide: one opener at a time.
std::mutex& DiscoveryMutex() {
  static std::mutex mutex;
  return mutex;
}

std::string TakeError(GError** error) {
  std::string text = (error && *error) ? (*error)->message : "unknown Aravis error";
  g_clear_error(error);
  return text;
}

double Seconds(Clock::duration duration) { return std::chrono::duration<double>(duration).count(); }

std::string Fixed(double value, int digits) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value;
  return out.str();
}

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

ArvPixelFormat ToArv(GigePixelFormat format) {
  switch (format) {
    case GigePixelFormat::kMono8: return ARV_PIXEL_FORMAT_MONO_8;
    case GigePixelFormat::kMono12: return ARV_PIXEL_FORMAT_MONO_12;
    case GigePixelFormat::kMono16: return ARV_PIXEL_FORMAT_MONO_16;
    case GigePixelFormat::kRgb8: return ARV_PIXEL_FORMAT_RGB_8_PACKED;
    case GigePixelFormat::kBayerRG8: return ARV_PIXEL_FORMAT_BAYER_RG_8;
    case GigePixelFormat::kBayerGR8: return ARV_PIXEL_FORMAT_BAYER_GR_8;
    case GigePixelFormat::kBayerGB8: return ARV_PIXEL_FORMAT_BAYER_GB_8;
    case GigePixelFormat::kBayerBG8: return ARV_PIXEL_FORMAT_BAYER_BG_8;
  }
  return ARV_PIXEL_FORMAT_MONO_8;
}

// OpenCV names Bayer patterns by the second row's second and third pixels, GenICam by the first
// row's first two: GenICam RG (R at 0,0) is OpenCV's BG.
int BayerToRgbCode(GigePixelFormat format) {
  switch (format) {
    case GigePixelFormat::kBayerRG8: return cv::COLOR_BayerBG2RGB;
    case GigePixelFormat::kBayerGR8: return cv::COLOR_BayerGB2RGB;
    case GigePixelFormat::kBayerGB8: return cv::COLOR_BayerGR2RGB;
    case GigePixelFormat::kBayerBG8: return cv::COLOR_BayerRG2RGB;
    default: return -1;
  }
}

}  // namespace

Image ConvertGigeImage(const std::uint8_t* data, std::size_t size, int width, int height,
                       GigePixelFormat format) {
  const int raw_bpp = (format == GigePixelFormat::kMono12 || format == GigePixelFormat::kMono16) ? 2
                      : format == GigePixelFormat::kRgb8                                       ? 3
                                                                                                : 1;
  const std::size_t needed = static_cast<std::size_t>(width) * height * raw_bpp;
  if (width <= 0 || height <= 0 || size < needed) {
    Fail("camera buffer of " + std::to_string(size) + " bytes is too small for " +
         std::to_string(width) + "x" + std::to_string(height) + " " + ToString(format));
  }
  Image image = Image::Allocate(DeliveredFormat(format), width, height);
  const int code = BayerToRgbCode(format);
  if (code < 0) {
    std::memcpy(image.data.data(), data, needed);
  } else {
    const cv::Mat raw(height, width, CV_8UC1, const_cast<std::uint8_t*>(data));
    cv::Mat rgb(height, width, CV_8UC3, image.data.data());
    cv::cvtColor(raw, rgb, code);
    ROMO_DEMAND(rgb.data == image.data.data());
  }
  return image;
}

class GigeSource::Impl {
 public:
  struct Rig;

  // One physical camera: its Aravis objects are touched only by its own thread (after start).
  struct Camera {
    Impl* owner = nullptr;
    Rig* rig = nullptr;
    bool is_left = true;
    GigeCameraRef ref;
    std::string label;  // "rig 0 left (ip:127.0.0.2)"

    ArvCamera* camera = nullptr;
    ArvStream* stream = nullptr;
    gulong lost_handler = 0;
    std::atomic<bool> control_lost{false};
    std::thread thread;

    // Guarded by owner->mutex_.
    CameraCounters counters;
    GigeCameraDiagnostics diagnostics;
    bool have_frame_id = false;
    std::uint64_t last_frame_id = 0;
    Clock::time_point last_frame_id_time;
    bool have_stamp = false;
    std::int64_t last_stamp_ns = 0;
    std::uint64_t stamp_jumps_back = 0;
    bool receive_buffer_reported = false;
    // Aravis statistics of earlier connections, so totals survive reconnects.
    std::uint64_t stats_completed = 0, stats_failures = 0, stats_underruns = 0;
  };

  struct Rig {
    GigeRigConfig config;
    const RigCalibration* calibration = nullptr;
    std::string calibration_origin;
    Camera left;
    Camera right;
    std::unique_ptr<StereoPairer> pairer;  // guarded by mutex_
    std::deque<std::pair<StereoFrame, Clock::time_point>> ready;  // guarded by mutex_
  };

  Impl(const GigeConfig& config, const std::string& origin) : config_(config), origin_(origin) {
    config_.Validate(origin);
    LoadCalibrations();
    rigs_.reserve(config_.rigs.size());
    for (const GigeRigConfig& rig_config : config_.rigs) {
      auto rig = std::make_unique<Rig>();
      rig->config = rig_config;
      rig->pairer = std::make_unique<StereoPairer>(
          rig_config.rig_id, static_cast<std::int64_t>(rig_config.pairing_tolerance_ms * 1e6),
          static_cast<std::size_t>(config_.buffers_per_camera));
      if (!rig_config.calibration_path.empty()) {
        rig->calibration = &calibration_.rig(rig_config.rig_id);
        rig->calibration_origin = rig_config.calibration_path;
      }
      for (bool is_left : {true, false}) {
        Camera& camera = is_left ? rig->left : rig->right;
        camera.owner = this;
        camera.rig = rig.get();
        camera.is_left = is_left;
        camera.ref = is_left ? rig_config.left : rig_config.right;
        camera.label = "rig " + std::to_string(rig_config.rig_id) + (is_left ? " left" : " right") +
                       " (" + camera.ref.Describe() + ")";
        camera.counters.camera_id = camera.ref.Describe();
        camera.diagnostics.camera_id = camera.ref.Describe();
      }
      min_period_s_ = std::min(min_period_s_, 1.0 / rig_config.frame_rate_hz);
      max_period_s_ = std::max(max_period_s_, 1.0 / rig_config.frame_rate_hz);
      rigs_.push_back(std::move(rig));
    }
    try {
      for (auto& rig : rigs_) {
        for (Camera* camera : {&rig->left, &rig->right}) OpenAtStart(camera);
      }
    } catch (...) {
      for (auto& rig : rigs_) {
        CloseCamera(&rig->left, /*stop=*/true);
        CloseCamera(&rig->right, /*stop=*/true);
      }
      throw;
    }
    // Acquisition starts only once every camera is configured, so all rigs begin together
    // instead of the first ones filling their buffer pools while the others are still opening.
    for (auto& rig : rigs_) {
      for (Camera* camera : {&rig->left, &rig->right}) {
        GError* error = nullptr;
        arv_camera_start_acquisition(camera->camera, &error);
        if (error) {
          const std::string why = TakeError(&error);
          for (auto& r : rigs_) {
            CloseCamera(&r->left, /*stop=*/true);
            CloseCamera(&r->right, /*stop=*/true);
          }
          Fail(origin_ + ": " + camera->label + ": cannot start acquisition: " + why);
        }
      }
    }
    for (auto& rig : rigs_) {
      for (Camera* camera : {&rig->left, &rig->right}) {
        camera->thread = std::thread([this, camera] { Run(camera); });
      }
    }
  }

  ~Impl() {
    stop_ = true;
    for (auto& rig : rigs_) {
      for (Camera* camera : {&rig->left, &rig->right}) {
        if (camera->thread.joinable()) camera->thread.join();
      }
    }
  }

  std::optional<FrameSet> Next() {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto stall_deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(config_.stall_timeout_s));
    // Rigs that have not delivered within three frame periods (at least 0.3 s: grab threads of
    // 12 cameras on a loaded machine lag) of the first are left out of the set. Only latency
    // grows: sets queued behind a late one are already complete.
    const auto assemble_wait = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(std::max(3.0 * max_period_s_, 0.3)));
    const std::int64_t set_tolerance_ns = static_cast<std::int64_t>(0.5 * min_period_s_ * 1e9);
    while (true) {
      const Rig* oldest = nullptr;
      bool all_ready = true;
      for (const auto& rig : rigs_) {
        if (rig->ready.empty()) {
          all_ready = false;
          continue;
        }
        if (!oldest || rig->ready.front().first.stamp_ns() < oldest->ready.front().first.stamp_ns()) {
          oldest = rig.get();
        }
      }
      const auto now = Clock::now();
      if (oldest) {
        const auto deadline = oldest->ready.front().second + assemble_wait;
        if (all_ready || now >= deadline) {
          const std::int64_t t0 = oldest->ready.front().first.stamp_ns();
          FrameSet set;
          set.stamp_ns = t0;
          set.sequence = next_sequence_++;
          for (auto& rig : rigs_) {
            if (!rig->ready.empty() && rig->ready.front().first.stamp_ns() - t0 <= set_tolerance_ns) {
              set.stereo.push_back(std::move(rig->ready.front().first));
              rig->ready.pop_front();
            }
          }
          return set;
        }
        ready_cv_.wait_until(lock, deadline);
      } else {
        if (now >= stall_deadline) {
          events_.push_back("gige: no frames for " + Fixed(config_.stall_timeout_s, 1) +
                            " s (stall_timeout_s): ending the stream");
          return std::nullopt;
        }
        ready_cv_.wait_until(lock, stall_deadline);
      }
    }
  }

  SourceStatus Status() {
    std::lock_guard<std::mutex> lock(mutex_);
    SourceStatus status;
    for (auto& rig : rigs_) {
      rig->left.counters.unpaired = rig->pairer->unpaired_left();
      rig->right.counters.unpaired = rig->pairer->unpaired_right();
      status.cameras.push_back(rig->left.counters);
      status.cameras.push_back(rig->right.counters);
    }
    status.events = events_;
    return status;
  }

  std::vector<GigeCameraDiagnostics> Diagnostics() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<GigeCameraDiagnostics> out;
    for (auto& rig : rigs_) {
      rig->left.counters.unpaired = rig->pairer->unpaired_left();
      rig->right.counters.unpaired = rig->pairer->unpaired_right();
      for (Camera* camera : {&rig->left, &rig->right}) {
        out.push_back(camera->diagnostics);
        out.back().counters = camera->counters;
      }
    }
    return out;
  }

  const Calibration* calibration() const { return calibration_.rigs.empty() ? nullptr : &calibration_; }

 private:
  void LoadCalibrations() {
    std::map<std::string, Calibration> files;
    for (const GigeRigConfig& rig : config_.rigs) {
      if (rig.calibration_path.empty()) continue;
      auto it = files.find(rig.calibration_path);
      if (it == files.end()) {
        it = files.emplace(rig.calibration_path, Calibration::Load(rig.calibration_path)).first;
      }
      try {
        calibration_.rigs.push_back(it->second.rig(rig.rig_id));
      } catch (const Error& e) {
        Fail(origin_ + ": rig " + std::to_string(rig.rig_id) + ": calibration '" +
             rig.calibration_path + "' has no rig " + std::to_string(rig.rig_id) + " (" + e.what() + ")");
      }
    }
  }

  void AddEvent(const std::string& text) {
    // Caller holds mutex_.
    events_.push_back(text);
  }

  static void OnControlLost(ArvDevice*, gpointer data) {
    static_cast<Camera*>(data)->control_lost = true;
  }

  // Opens and configures @p camera and starts acquisition. Returns an empty string on success,
  // otherwise what went wrong; *fatal says whether retrying cannot help (configuration errors).
  std::string TryOpen(Camera* camera, bool* fatal, bool start = true) {
    *fatal = false;
    const GigeRigConfig& rig = camera->rig->config;
    GError* error = nullptr;
    ArvCamera* handle = nullptr;
    {
      std::lock_guard<std::mutex> lock(DiscoveryMutex());
      std::string device_id = camera->ref.address;
      if (device_id.empty()) {
        arv_update_device_list();
        for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
          const char* serial = arv_get_device_serial_nbr(i);
          if (serial && camera->ref.serial == serial) device_id = arv_get_device_id(i);
        }
        if (device_id.empty()) return "no camera with serial number '" + camera->ref.serial + "' answers discovery";
      }
      handle = arv_camera_new(device_id.c_str(), &error);
    }
    if (!handle) return "cannot open: " + TakeError(&error);

    auto failed = [&](const std::string& what, const std::string& value) {
      const std::string text = what + " = " + value + " refused by the camera: " + TakeError(&error);
      g_object_unref(handle);
      *fatal = true;
      return text;
    };
    arv_camera_set_pixel_format(handle, ToArv(rig.pixel_format), &error);
    if (error) return failed("pixel_format", ToString(rig.pixel_format));
    if (arv_camera_is_gv_device(handle)) {
      if (rig.packet_size_bytes > 0) {
        arv_camera_gv_set_packet_size(handle, rig.packet_size_bytes, &error);
        if (error) return failed("packet_size", std::to_string(rig.packet_size_bytes));
      } else {
        // Negotiation is best effort: a camera without test packets keeps its default size.
        arv_camera_gv_auto_packet_size(handle, &error);
        g_clear_error(&error);
      }
    }
    // Setting the frame rate turns triggering off, so the software trigger comes after it.
    arv_camera_set_frame_rate(handle, rig.frame_rate_hz, &error);
    if (error) return failed("frame_rate_hz", Fixed(rig.frame_rate_hz, 3));
    if (rig.trigger == TriggerMode::kSoftware) {
      arv_camera_set_trigger(handle, "Software", &error);
      if (error) return failed("trigger", "software");
    }
    arv_camera_set_exposure_time(handle, rig.exposure_us, &error);
    if (error) return failed("exposure_us", Fixed(rig.exposure_us, 1));
    arv_camera_set_gain(handle, rig.gain_db, &error);
    if (error) return failed("gain_db", Fixed(rig.gain_db, 2));

    gint x = 0, y = 0, width = 0, height = 0;
    arv_camera_get_region(handle, &x, &y, &width, &height, &error);
    if (error) return failed("region", "?");
    if (const RigCalibration* calib = camera->rig->calibration) {
      if (width != calib->width_px || height != calib->height_px) {
        g_object_unref(handle);
        *fatal = true;
        return "image size mismatch: the camera sends " + std::to_string(width) + "x" +
               std::to_string(height) + " but calibration '" + camera->rig->calibration_origin +
               "' rig " + std::to_string(rig.rig_id) + " has width_px x height_px = " +
               std::to_string(calib->width_px) + "x" + std::to_string(calib->height_px);
      }
    }
    const guint payload = arv_camera_get_payload(handle, &error);
    if (error || payload == 0) return failed("payload", std::to_string(payload));

    // Aravis' packet-socket receiver (taken when running with CAP_NET_RAW) opens an AF_PACKET
    // socket that sees every packet on the host until its filter is attached, and parses what it
    // caught as this camera's stream: a reopen amid streaming cameras got another camera's frame.
    // The kernel's UDP port demultiplexing never mixes cameras.
    if (!config_.packet_socket) {
      arv_camera_gv_set_stream_options(handle, ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    }
    ArvStream* stream = arv_camera_create_stream(handle, nullptr, nullptr, &error);
    if (!stream) {
      const std::string text = "cannot create the stream: " + TakeError(&error);
      g_object_unref(handle);
      return text;
    }
    if (!config_.packet_socket) SizeReceiveBuffer(camera, stream, payload);
    for (int i = 0; i < config_.buffers_per_camera; ++i) {
      arv_stream_push_buffer(stream, arv_buffer_new(payload, nullptr));
    }
    camera->control_lost = false;
    camera->lost_handler = g_signal_connect(arv_camera_get_device(handle), "control-lost",
                                            G_CALLBACK(&Impl::OnControlLost), camera);
    if (start) arv_camera_start_acquisition(handle, &error);
    if (error) {
      const std::string text = "cannot start acquisition: " + TakeError(&error);
      g_signal_handler_disconnect(arv_camera_get_device(handle), camera->lost_handler);
      g_object_unref(stream);
      g_object_unref(handle);
      return text;
    }
    // The last block id is kept: a camera reopened after a stall goes on counting, so the frames
    // it sent while nobody received them are counted lost (Deliver tells a restart from a gap).
    camera->camera = handle;
    camera->stream = stream;
    return "";
  }

  // A frame arrives as one burst of packets; the UDP socket must hold a few whole frames or the
  // kernel drops the tail of each (the usual default receive buffer is smaller than one frame).
  // Sized here, before the first frame: Aravis would only size it once packets arrive. Without
  // CAP_NET_ADMIN the kernel caps it at net.core.rmem_max, which is then said once per camera.
  void SizeReceiveBuffer(Camera* camera, ArvStream* stream, guint payload) {
    const int wanted = static_cast<int>(std::min<std::uint64_t>(4ull * payload, 64ull << 20));
    int size = 0;
    const int fd = StreamSocket(arv_gv_stream_get_port(ARV_GV_STREAM(stream)));
    if (fd >= 0) {
      if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &wanted, sizeof wanted) != 0) {
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &wanted, sizeof wanted);
      }
      socklen_t length = sizeof size;
      getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, &length);
      size /= 2;  // Linux reports twice the size asked for (its bookkeeping overhead)
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (size >= 2 * static_cast<int>(payload) || camera->receive_buffer_reported) return;
    camera->receive_buffer_reported = true;
    AddEvent("gige: " + camera->label + ": " +
             (fd < 0 ? std::string("stream socket not found, receive buffer left as it is")
                     : "receive buffer " + std::to_string(size) + " bytes") +
             ", under two frames (" + std::to_string(2ull * payload) +
             "): frames may arrive incomplete; raise net.core.rmem_max to " + std::to_string(wanted) +
             " or set packet_socket: true");
  }

  // Aravis keeps its stream socket to itself: it is this process's UDP socket bound to @p port.
  static int StreamSocket(guint16 port) {
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd", error)) {
      const int fd = std::atoi(entry.path().filename().c_str());
      sockaddr_in address{};
      socklen_t length = sizeof address;
      int type = 0;
      socklen_t type_length = sizeof type;
      if (getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0 &&
          address.sin_family == AF_INET && ntohs(address.sin_port) == port &&
          getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &type_length) == 0 && type == SOCK_DGRAM) {
        return fd;
      }
    }
    return -1;
  }

  void CloseCamera(Camera* camera, bool stop) {
    if (!camera->camera) return;
    if (camera->stream) {
      guint64 completed = 0, failures = 0, underruns = 0;
      arv_stream_get_statistics(camera->stream, &completed, &failures, &underruns);
      std::lock_guard<std::mutex> lock(mutex_);
      camera->stats_completed += completed;
      camera->stats_failures += failures;
      camera->stats_underruns += underruns;
    }
    // A camera that vanished would only time out on the stop command.
    if (stop) arv_camera_stop_acquisition(camera->camera, nullptr);
    g_signal_handler_disconnect(arv_camera_get_device(camera->camera), camera->lost_handler);
    if (camera->stream) g_object_unref(camera->stream);
    g_object_unref(camera->camera);
    camera->stream = nullptr;
    camera->camera = nullptr;
  }

  void OpenAtStart(Camera* camera) {
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(config_.discovery_timeout_s));
    std::string why;
    while (true) {
      bool fatal = false;
      why = TryOpen(camera, &fatal, /*start=*/false);
      if (why.empty()) return;
      if (fatal) Fail(origin_ + ": " + camera->label + ": " + why);
      if (Clock::now() >= deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    std::string seen;
    for (const GigeDeviceInfo& device : DiscoverGigeCameras()) {
      seen += (seen.empty() ? "" : "; ") + device.id + " serial " + device.serial + " at " + device.address;
    }
    Fail(origin_ + ": " + camera->label + ": camera not found within discovery_timeout_s = " +
         Fixed(config_.discovery_timeout_s, 1) + " s (" + why + "); cameras seen: " +
         (seen.empty() ? "none" : seen));
  }

  // Returns whether the buffer carries a block id, i.e. the camera sent at least one packet of it.
  bool Deliver(Camera* camera, ArvBuffer* buffer) {
    const ArvBufferStatus buffer_status = arv_buffer_get_status(buffer);
    const std::uint64_t frame_id = arv_buffer_get_frame_id(buffer);
    std::optional<CameraFrame> frame;
    std::string convert_error;
    if (buffer_status == ARV_BUFFER_STATUS_SUCCESS) {
      size_t size = 0;
      const void* data = arv_buffer_get_data(buffer, &size);
      try {
        CameraFrame out;
        out.image = ConvertGigeImage(static_cast<const std::uint8_t*>(data), size,
                                     arv_buffer_get_image_width(buffer),
                                     arv_buffer_get_image_height(buffer),
                                     camera->rig->config.pixel_format);
        out.stamp_ns = static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer));
        out.sequence = frame_id;
        out.camera_id = camera->ref.Describe();
        frame = std::move(out);
      } catch (const Error& e) {
        convert_error = e.what();
      }
    }
    const auto now = Clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    CameraCounters& counters = camera->counters;
    std::uint64_t gap = 0;
    // Block id 0 is never sent (GigE Vision): such a buffer never got a packet to say which frame
    // it was, and must not become the reference for the next gap.
    const bool have_id = frame_id != 0;
    if (have_id && camera->have_frame_id) {
      gap = FrameIdGap(camera->last_frame_id, frame_id);
      // A camera restarted behind our back (power cycle, new process) starts its block ids
      // anywhere: ids further ahead than it can have sent since the last one are no loss. The
      // second of slack covers frames delivered late (Aravis frame retention, a starved thread).
      const double possible = (Seconds(now - camera->last_frame_id_time) + 1.0) *
                                  camera->rig->config.frame_rate_hz + 2.0;
      if (static_cast<double>(gap) > possible) {
        AddEvent("gige: " + camera->label + ": block id went from " +
                 std::to_string(camera->last_frame_id) + " to " + std::to_string(frame_id) + " in " +
                 Fixed(Seconds(now - camera->last_frame_id_time), 2) +
                 " s, more than the camera can send: taken for a camera restart, not counted lost");
        gap = 0;
      }
    }
    counters.dropped += gap;
    camera->diagnostics.frame_ids_spanned += gap + 1;
    if (have_id) {
      camera->have_frame_id = true;
      camera->last_frame_id = frame_id;
      camera->last_frame_id_time = now;
    }
    if (frame) {
      // Device clocks only grow; one going back was reset (power cycle, PTP step). The frames are
      // kept (the pairer starts over), the jump is reported.
      if (camera->have_stamp && frame->stamp_ns < camera->last_stamp_ns) {
        ++camera->stamp_jumps_back;
        AddEvent("gige: " + camera->label + ": device timestamp went back by " +
                 Fixed(1e-9 * static_cast<double>(camera->last_stamp_ns - frame->stamp_ns), 3) +
                 " s (camera clock reset; jump " + std::to_string(camera->stamp_jumps_back) + ")");
      }
      camera->have_stamp = true;
      camera->last_stamp_ns = frame->stamp_ns;
    }
    if (!frame) {
      ++counters.incomplete;
      if (!convert_error.empty() && counters.incomplete == 1) {
        AddEvent("gige: " + camera->label + ": bad buffer: " + convert_error);
      }
      return have_id;
    }
    ++counters.completed;
    Rig& rig = *camera->rig;
    if (camera->is_left) {
      rig.pairer->PushLeft(std::move(*frame));
    } else {
      rig.pairer->PushRight(std::move(*frame));
    }
    bool added = false;
    while (auto pair = rig.pairer->Pop()) {
      rig.ready.emplace_back(std::move(*pair), Clock::now());
      added = true;
    }
    // The consumer fell behind: the oldest pairs go, counted on both cameras.
    while (rig.ready.size() > static_cast<std::size_t>(2 * config_.buffers_per_camera)) {
      rig.ready.pop_front();
      for (Camera* side : {&rig.left, &rig.right}) {
        ++side->counters.dropped;
        ++side->diagnostics.queue_dropped;
      }
    }
    if (added) ready_cv_.notify_all();
    return true;
  }

  void Run(Camera* camera) {
    const GigeRigConfig& rig = camera->rig->config;
    const auto period = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(1.0 / rig.frame_rate_hz));
    const auto lost_after = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(std::max(config_.lost_timeout_s, 3.0 / rig.frame_rate_hz)));
    auto last_frame = Clock::now();
    auto lost_since = last_frame;
    bool waiting_first_frame = false;
    // An outage lasts from the first missed frame to the next frame, across reopen attempts; a
    // camera that reopens but still sends nothing is stalled (alive on GVCP, silent on GVSP).
    bool in_outage = false;
    bool stall_reported = false;
    double backoff_s = 0.1;
    auto next_attempt = Clock::now();
    // Software triggers go out on a grid shared by every camera of the process, so both cameras
    // of a rig are triggered within the same few milliseconds.
    auto next_trigger = Clock::time_point((Clock::now().time_since_epoch() / period + 1) * period);
    std::string last_failure;
    while (!stop_) {
      if (!camera->camera) {
        const auto now = Clock::now();
        if (now < next_attempt) {
          std::this_thread::sleep_for(std::min<Clock::duration>(next_attempt - now, std::chrono::milliseconds(50)));
          continue;
        }
        bool fatal = false;
        const std::string why = TryOpen(camera, &fatal);
        if (!why.empty()) {
          if (why != last_failure) {
            std::lock_guard<std::mutex> lock(mutex_);
            AddEvent("gige: " + camera->label + ": reopen failed: " + why);
            last_failure = why;
          }
          next_attempt = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                            std::chrono::duration<double>(backoff_s));
          backoff_s = std::min(2.0 * backoff_s, config_.max_backoff_s);
          continue;
        }
        last_failure.clear();
        backoff_s = 0.1;
        const bool first_reopen = !waiting_first_frame;
        waiting_first_frame = true;
        last_frame = Clock::now();
        std::lock_guard<std::mutex> lock(mutex_);
        ++camera->counters.reconnects;
        if (first_reopen) {
          AddEvent("gige: " + camera->label + ": reopened (reconnect " +
                   std::to_string(camera->counters.reconnects) + ")");
        }
      }
      if (rig.trigger == TriggerMode::kSoftware && Clock::now() >= next_trigger) {
        GError* error = nullptr;
        arv_camera_software_trigger(camera->camera, &error);
        g_clear_error(&error);  // a lost camera shows up as missing frames below
        while (next_trigger <= Clock::now()) next_trigger += period;
      }
      ArvBuffer* buffer = arv_stream_timeout_pop_buffer(camera->stream, 20000);
      const auto now = Clock::now();
      // Aravis may hand back a buffer no packet reached (seen after reopening a stalled camera):
      // that is no sign of the camera, so it neither ends an outage nor postpones one.
      bool camera_sent = false;
      if (buffer) {
        camera_sent = Deliver(camera, buffer);
        arv_stream_push_buffer(camera->stream, buffer);
      }
      if (camera_sent) {
        if (waiting_first_frame && camera->counters.reconnects > 0) {
          const auto gap = now - lost_since;
          std::lock_guard<std::mutex> lock(mutex_);
          camera->counters.gap_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(gap).count();
          AddEvent("gige: " + camera->label + ": frames again after reconnect " +
                   std::to_string(camera->counters.reconnects) + ", gap " + Fixed(Seconds(gap), 3) + " s" +
                   (stall_reported ? " (was stalled)" : ""));
        }
        waiting_first_frame = false;
        in_outage = false;
        stall_reported = false;
        last_frame = now;
      } else if (camera->control_lost || now - last_frame > lost_after) {
        if (!in_outage) {
          in_outage = true;
          lost_since = last_frame;
          std::lock_guard<std::mutex> lock(mutex_);
          AddEvent("gige: " + camera->label + ": camera lost (" +
                   (camera->control_lost ? std::string("control channel lost")
                                         : "no frame for " + Fixed(Seconds(now - last_frame), 2) + " s") +
                   "); reopening with back-off");
        } else if (waiting_first_frame && !camera->control_lost && !stall_reported) {
          stall_reported = true;
          std::lock_guard<std::mutex> lock(mutex_);
          AddEvent("gige: " + camera->label + ": camera stalled (reopened, answers control, but no "
                   "frame for " + Fixed(Seconds(now - last_frame), 2) + " s); retrying");
        }
        CloseCamera(camera, /*stop=*/false);
        next_attempt = now;
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        camera->diagnostics.thread_cpu_s = ThreadCpuSeconds();
        if (camera->stream) {
          guint64 completed = 0, failures = 0, underruns = 0;
          arv_stream_get_statistics(camera->stream, &completed, &failures, &underruns);
          camera->diagnostics.aravis_completed = camera->stats_completed + completed;
          camera->diagnostics.aravis_failures = camera->stats_failures + failures;
          camera->diagnostics.aravis_underruns = camera->stats_underruns + underruns;
        }
      }
    }
    CloseCamera(camera, /*stop=*/true);
  }

  GigeConfig config_;
  std::string origin_;
  Calibration calibration_;
  std::vector<std::unique_ptr<Rig>> rigs_;
  double min_period_s_ = 1e9;
  double max_period_s_ = 0.0;
  std::atomic<bool> stop_{false};

  std::mutex mutex_;
  std::condition_variable ready_cv_;
  std::vector<std::string> events_;
  std::uint64_t next_sequence_ = 0;
};

GigeSource::GigeSource(const GigeConfig& config, const std::string& origin)
    : impl_(std::make_unique<Impl>(config, origin)) {}
GigeSource::~GigeSource() = default;
std::optional<FrameSet> GigeSource::Next() { return impl_->Next(); }
const Calibration* GigeSource::calibration() const { return impl_->calibration(); }
SourceStatus GigeSource::status() const { return impl_->Status(); }
std::vector<GigeCameraDiagnostics> GigeSource::diagnostics() const { return impl_->Diagnostics(); }

std::unique_ptr<FrameSource> OpenGigeSource(const Uri& uri) {
  if (uri.path.empty()) Fail("gige:// needs a rig configuration file: gige://<rigs.yaml>");
  GigeConfig config = GigeConfig::Load(uri.path);
  for (const auto& [key, value] : uri.query) {
    if (key == "stall_timeout_s") {
      config.stall_timeout_s = *uri.GetDouble(key);
    } else if (key == "discovery_timeout_s") {
      config.discovery_timeout_s = *uri.GetDouble(key);
    } else if (key == "lost_timeout_s") {
      config.lost_timeout_s = *uri.GetDouble(key);
    } else {
      Fail("gige://" + uri.path + ": unknown query key '" + key + "' = '" + value +
           "' (known: stall_timeout_s, discovery_timeout_s, lost_timeout_s)");
    }
  }
  return std::make_unique<GigeSource>(config, uri.path);
}

std::vector<GigeDeviceInfo> DiscoverGigeCameras() {
  std::lock_guard<std::mutex> lock(DiscoveryMutex());
  arv_update_device_list();
  std::vector<GigeDeviceInfo> devices;
  auto text = [](const char* value) { return std::string(value ? value : ""); };
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
    GigeDeviceInfo info;
    info.id = text(arv_get_device_id(i));
    info.vendor = text(arv_get_device_vendor(i));
    info.model = text(arv_get_device_model(i));
    info.serial = text(arv_get_device_serial_nbr(i));
    info.address = text(arv_get_device_address(i));
    info.protocol = text(arv_get_device_protocol(i));
    devices.push_back(std::move(info));
  }
  return devices;
}

}  // namespace romo::drivers
