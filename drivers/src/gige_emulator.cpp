// Emulated GigE Vision cameras (Aravis GV fake cameras) serving given images through the real
// GVCP/GVSP protocol, for `romo gige-serve`, hardware-in-loop tests and the gige benchmark.
#include <arv.h>

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstring>
#include <mutex>
#include <utility>
#include <vector>

#include "romo/core/check.hpp"
#include "romo/drivers/gige.hpp"

namespace romo::drivers {
namespace {

ArvPixelFormat ArvFormatOf(PixelFormat format) {
  switch (format) {
    case PixelFormat::kMono8: return ARV_PIXEL_FORMAT_MONO_8;
    case PixelFormat::kMono16: return ARV_PIXEL_FORMAT_MONO_16;
    case PixelFormat::kRgb8: return ARV_PIXEL_FORMAT_RGB_8_PACKED;
  }
  return ARV_PIXEL_FORMAT_MONO_8;
}

}  // namespace

class GigeEmulator::Impl {
 public:
  struct Served {
    Impl* owner = nullptr;
    Camera camera;
    ArvPixelFormat format = ARV_PIXEL_FORMAT_MONO_8;
    ArvGvFakeCamera* gv = nullptr;
    std::atomic<std::uint64_t> served{0};
    std::atomic<std::int64_t> last_index{-1};
    std::atomic<std::uint64_t> mismatched{0};
    std::atomic<bool> stalled{false};
    std::atomic<std::uint64_t> stalled_frames{0};
  };

  Impl(std::vector<Camera> cameras, double rate_hz, bool loop) : loop_(loop) {
    if (cameras.empty()) Fail("gige emulator: no cameras to serve");
    if (!(rate_hz > 0.0 && rate_hz <= 1000.0)) {
      Fail("gige emulator: rate " + std::to_string(rate_hz) + " Hz must be in (0, 1000]");
    }
    // Whole microseconds: the fake camera's period register, and so its wake-up grid, is in µs.
    period_ns_ = 1000 * static_cast<std::int64_t>(1e6 / rate_hz);
    for (auto& camera : cameras) {
      const std::string what = "gige emulator: camera " + camera.serial + " at " + camera.address;
      if (camera.serial.empty() || camera.serial.size() > 15) {
        Fail(what + ": serial must have 1 to 15 characters (GigE Vision limit)");
      }
      if (camera.frames.empty()) Fail(what + ": no frames to serve");
      const Image& first = camera.frames.front();
      for (const Image& frame : camera.frames) {
        frame.Validate();
        if (frame.width != first.width || frame.height != first.height || frame.format != first.format) {
          Fail(what + ": frames differ in size or format (" + std::to_string(frame.width) + "x" +
               std::to_string(frame.height) + " vs " + std::to_string(first.width) + "x" +
               std::to_string(first.height) + ")");
        }
      }
      auto served = std::make_unique<Served>();
      served->owner = this;
      served->format = ArvFormatOf(first.format);
      served->camera = std::move(camera);
      cameras_.push_back(std::move(served));
    }
    for (auto& served : cameras_) Start(served.get());
  }

  ~Impl() {
    for (auto& served : cameras_) {
      if (served->gv) g_object_unref(served->gv);
    }
  }

  std::vector<std::uint64_t> FramesServed() const {
    std::vector<std::uint64_t> out;
    for (const auto& served : cameras_) out.push_back(served->served.load());
    return out;
  }

  void SetPacketLoss(double ratio) {
    if (!(ratio >= 0.0 && ratio <= 1.0)) {
      Fail("gige emulator: packet loss ratio " + std::to_string(ratio) + " must be in [0, 1]");
    }
    loss_ratio_ = ratio;
    for (auto& served : cameras_) {
      if (!served->stalled) g_object_set(served->gv, "gvsp-lost-ratio", ratio, nullptr);
    }
  }

  void SetStalled(std::size_t camera, bool stalled) {
    if (camera >= cameras_.size()) {
      Fail("gige emulator: camera index " + std::to_string(camera) + " out of range (" +
           std::to_string(cameras_.size()) + " cameras)");
    }
    Served& served = *cameras_[camera];
    served.stalled = stalled;
    // Every GVSP packet dropped: the camera still answers GVCP (discovery, heartbeats, register
    // access) on its own socket, so to a client it looks alive but silent.
    g_object_set(served.gv, "gvsp-lost-ratio", stalled ? 1.0 : loss_ratio_.load(), nullptr);
  }

  void ShiftStamps(std::int64_t offset_ns) {
    std::lock_guard<std::mutex> lock(shift_mutex_);
    // Applied from a tick no camera has filled yet, so both cameras of a rig shift together.
    const std::int64_t from = latest_tick_.load() + 2;
    shifts_.push_back({from, offset_ns});
  }

  std::vector<std::uint64_t> FramesStalled() const {
    std::vector<std::uint64_t> out;
    for (const auto& served : cameras_) out.push_back(served->stalled_frames.load());
    return out;
  }

  bool Finished() const {
    if (loop_) return false;
    for (const auto& served : cameras_) {
      if (served->last_index.load() + 1 < static_cast<std::int64_t>(served->camera.frames.size())) {
        return false;
      }
    }
    return true;
  }

 private:
  void Start(Served* served) {
    const Camera& camera = served->camera;
    served->gv = arv_gv_fake_camera_new(camera.address.c_str(), camera.serial.c_str());
    if (!served->gv || !arv_gv_fake_camera_is_running(served->gv)) {
      Fail("gige emulator: cannot serve camera " + camera.serial + " at " + camera.address +
           " (address not on an interface, or already taken by another emulator)");
    }
    ArvFakeCamera* fake = arv_gv_fake_camera_get_fake_camera(served->gv);
    const Image& first = camera.frames.front();
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_SENSOR_WIDTH,
                                   std::max<guint32>(first.width, 2048));
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_SENSOR_HEIGHT,
                                   std::max<guint32>(first.height, 2048));
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_WIDTH, first.width);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_HEIGHT, first.height);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT, served->format);
    arv_fake_camera_write_register(fake, ARV_FAKE_CAMERA_REGISTER_ACQUISITION_FRAME_PERIOD_US,
                                   static_cast<guint32>(period_ns_ / 1000));
    arv_fake_camera_set_fill_pattern(fake, &Impl::Fill, served);
  }

  // Runs on the fake camera's thread for each frame it sends.
  static void Fill(ArvBuffer* buffer, void* data, guint32 /*exposure_us*/, guint32 /*gain*/,
                   ArvPixelFormat pixel_format) {
    auto* served = static_cast<Served*>(data);
    Impl* self = served->owner;
    // Aravis' fake camera wakes on multiples of its frame period in real time and stamps the fill
    // with the real time it actually ran, so a starved thread is only ever late. Flooring to the
    // grid point it woke for (not rounding to the nearest) keeps a frame up to a whole period late
    // on its own tick: stamps never repeat, and every camera agrees on the recording index.
    const auto stamp = static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer));
    const std::int64_t tick = stamp / self->period_ns_;
    std::int64_t first = self->first_tick_.load();
    if (first == LLONG_MIN) {
      self->first_tick_.compare_exchange_strong(first, tick);
      first = self->first_tick_.load();
    }
    const auto count = static_cast<std::int64_t>(served->camera.frames.size());
    std::int64_t index = std::max<std::int64_t>(0, tick - first);
    index = self->loop_ ? index % count : std::min(index, count - 1);
    served->last_index = std::max<std::int64_t>(served->last_index.load(), tick - first);
    std::int64_t latest = self->latest_tick_.load();
    while (tick > latest && !self->latest_tick_.compare_exchange_weak(latest, tick)) {
    }
    if (served->stalled) ++served->stalled_frames;

    const Image& image = served->camera.frames[static_cast<std::size_t>(index)];
    const int width = static_cast<int>(arv_buffer_get_image_width(buffer));
    const int height = static_cast<int>(arv_buffer_get_image_height(buffer));
    size_t unused_size = 0;  // reports 0 with a custom fill pattern
    auto* out = static_cast<std::uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, &unused_size)));
    const std::size_t row_bytes = static_cast<std::size_t>(width) * (ARV_PIXEL_FORMAT_BIT_PER_PIXEL(pixel_format) / 8);
    if (width == image.width && height == image.height && pixel_format == served->format) {
      for (int y = 0; y < height; ++y) std::memcpy(out + y * row_bytes, image.row(y), row_bytes);
    } else {
      // The client changed size or format: send black rather than misread memory, and count it.
      std::memset(out, 0, row_bytes * height);
      ++served->mismatched;
    }
    arv_buffer_set_timestamp(buffer, static_cast<guint64>(tick * self->period_ns_ +
                                                          self->ShiftAt(tick)));
    ++served->served;
  }

  std::int64_t ShiftAt(std::int64_t tick) {
    std::lock_guard<std::mutex> lock(shift_mutex_);
    std::int64_t total = 0;
    for (const auto& [from, offset] : shifts_) {
      if (tick >= from) total += offset;
    }
    return total;
  }

  bool loop_;
  std::int64_t period_ns_ = 0;
  std::atomic<double> loss_ratio_{0.0};
  std::atomic<std::int64_t> latest_tick_{LLONG_MIN};
  std::mutex shift_mutex_;
  std::vector<std::pair<std::int64_t, std::int64_t>> shifts_;  // (from tick, offset ns)
  std::atomic<std::int64_t> first_tick_{LLONG_MIN};
  std::vector<std::unique_ptr<Served>> cameras_;
};

GigeEmulator::GigeEmulator(std::vector<Camera> cameras, double rate_hz, bool loop)
    : impl_(std::make_unique<Impl>(std::move(cameras), rate_hz, loop)) {}
GigeEmulator::~GigeEmulator() = default;
std::vector<std::uint64_t> GigeEmulator::frames_served() const { return impl_->FramesServed(); }
bool GigeEmulator::finished() const { return impl_->Finished(); }
void GigeEmulator::SetPacketLoss(double ratio) { impl_->SetPacketLoss(ratio); }
void GigeEmulator::SetStalled(std::size_t camera, bool stalled) { impl_->SetStalled(camera, stalled); }
void GigeEmulator::ShiftStamps(std::int64_t offset_ns) { impl_->ShiftStamps(offset_ns); }
std::vector<std::uint64_t> GigeEmulator::frames_stalled() const { return impl_->FramesStalled(); }

}  // namespace romo::drivers
