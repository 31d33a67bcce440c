#pragma once
/// GigE Vision stereo rigs over Aravis 0.8: the rig configuration (YAML), the `gige://` frame
/// source, left/right pairing by device timestamp, and the emulated cameras behind
/// `romo gige-serve`. Aravis and GLib stay behind pimpl: nothing here includes them.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/frames.hpp"

namespace romo::drivers {

/// Pixel formats a GigE camera is asked to send (GenICam names). What the source delivers:
/// Mono8 -> kMono8; Mono12 / Mono16 -> kMono16 with the camera's sample values unchanged (a 12-bit
/// camera gives 0-4095); RGB8 -> kRgb8; Bayer*8 -> kRgb8 after demosaicing.
enum class GigePixelFormat : std::uint8_t {
  kMono8, kMono12, kMono16, kRgb8, kBayerRG8, kBayerGR8, kBayerGB8, kBayerBG8
};
/// GenICam name, e.g. "Mono12", "BayerRG8".
const char* ToString(GigePixelFormat format);
/// Parses a GenICam name; std::nullopt when unknown.
std::optional<GigePixelFormat> ParseGigePixelFormat(const std::string& name);
/// The romo image format the source delivers for @p format.
PixelFormat DeliveredFormat(GigePixelFormat format);

enum class TriggerMode : std::uint8_t {
  kFreeRun,   ///< the camera runs at frame_rate_hz on its own clock
  kSoftware,  ///< romo sends a software trigger to both cameras of the rig at frame_rate_hz
};
const char* ToString(TriggerMode mode);  ///< "free-run", "software"

/// One camera, found by serial number (GenICam DeviceSerialNumber) or by IPv4 address.
struct GigeCameraRef {
  std::string serial;
  std::string address;
  /// "serial:XYZ" or "ip:10.0.0.2", used as CameraFrame::camera_id and in counters.
  std::string Describe() const;
};

struct GigeRigConfig {
  int rig_id = 0;
  std::string name;  ///< optional, e.g. "front"
  GigeCameraRef left;
  GigeCameraRef right;
  GigePixelFormat pixel_format = GigePixelFormat::kMono8;
  double exposure_us = 10000.0;
  double gain_db = 0.0;
  double frame_rate_hz = 10.0;
  int packet_size_bytes = 0;  ///< GVSP packet size; 0 = negotiate the largest that passes
  TriggerMode trigger = TriggerMode::kFreeRun;
  double pairing_tolerance_ms = 5.0;  ///< left/right device stamps further apart are not a pair
  std::string calibration_path;       ///< optional; relative paths are relative to the YAML file
};

/// A rig configuration file: any number of rigs plus acquisition settings.
struct GigeConfig {
  std::vector<GigeRigConfig> rigs;
  double discovery_timeout_s = 5.0;  ///< a camera not found within this is an error at start
  double lost_timeout_s = 1.0;       ///< a free-running camera silent this long is reopened
  double max_backoff_s = 2.0;        ///< reopen attempts back off 0.1 s, 0.2 s, ... up to this
  double stall_timeout_s = 30.0;     ///< Next() ends the stream after this long without frames
  int buffers_per_camera = 8;        ///< Aravis buffer pool per camera
  /// Receive through Aravis' AF_PACKET ring (needs CAP_NET_RAW): about a third of the CPU, but
  /// until its filter is on, a reopened camera's ring catches other cameras' packets as its own.
  bool packet_socket = false;

  /// Reads and validates @p path.
  /// @throws romo::Error naming the file, the field (e.g. "rigs[1].right.address") and the value.
  static GigeConfig Load(const std::string& path);
  /// Same from YAML text; @p origin names it in errors, @p base_dir resolves relative paths.
  static GigeConfig FromYaml(const std::string& yaml_text, const std::string& origin,
                             const std::string& base_dir = "");
  std::string ToYaml() const;
  void Save(const std::string& path) const;
  /// @throws romo::Error naming @p origin, field and value.
  void Validate(const std::string& origin) const;
};

/// What the pairing logic decides for the two oldest pending stamps of a rig.
enum class PairDecision { kPair, kLeftUnpaired, kRightUnpaired };
/// Pure decision over device timestamps: a pair when |left - right| <= tolerance, otherwise the
/// older frame can never be paired (stamps of one camera only grow) and is given up.
PairDecision DecidePair(std::int64_t left_ns, std::int64_t right_ns, std::int64_t tolerance_ns);

/// Converts a raw camera image of @p format (packed rows of width x bytes per pixel) into the image
/// the source delivers (see GigePixelFormat). @throws romo::Error when @p size is too small.
Image ConvertGigeImage(const std::uint8_t* data, std::size_t size, int width, int height,
                       GigePixelFormat format);

/// Frames the camera sent but romo never received, from GVSP block ids @p previous -> @p current.
/// Handles the 16-bit block id wrap (65535 -> 1, 0 is never used); a camera restart (ids going
/// back) is no gap.
std::uint64_t FrameIdGap(std::uint64_t previous, std::uint64_t current);

/// Pairs the left and right frames of one rig by device timestamp. No network, no threads: the
/// source feeds it from its camera threads under a lock, tests feed it stamps.
class StereoPairer {
 public:
  /// @param max_pending frames kept per side waiting for a partner (the partner may be gone).
  StereoPairer(int rig_id, std::int64_t tolerance_ns, std::size_t max_pending = 8);

  void PushLeft(CameraFrame frame);
  void PushRight(CameraFrame frame);
  /// The oldest completed pair, if any.
  std::optional<StereoFrame> Pop();

  std::uint64_t unpaired_left() const { return unpaired_left_; }
  std::uint64_t unpaired_right() const { return unpaired_right_; }

 private:
  void Match();

  int rig_id_;
  std::int64_t tolerance_ns_;
  std::size_t max_pending_;
  std::deque<CameraFrame> left_;
  std::deque<CameraFrame> right_;
  std::deque<StereoFrame> pairs_;
  std::uint64_t unpaired_left_ = 0;
  std::uint64_t unpaired_right_ = 0;
};

/// Per-camera diagnostics beyond CameraCounters, for accounting checks: which GVSP block ids were
/// seen and what Aravis's own stream statistics say.
struct GigeCameraDiagnostics {
  std::string camera_id;
  CameraCounters counters;              ///< taken under the same lock as the fields below
  std::uint64_t frame_ids_spanned = 0;  ///< frames the camera sent between first and last id seen
  std::uint64_t aravis_completed = 0;   ///< arv_stream_get_statistics, summed over reconnects
  std::uint64_t aravis_failures = 0;
  std::uint64_t aravis_underruns = 0;
  std::uint64_t queue_dropped = 0;      ///< completed frames discarded: consumer too slow
  double thread_cpu_s = 0.0;            ///< CPU time of romo's grab thread for this camera
};

/// The live `gige://<rig-config.yaml>` source: one grab thread and buffer pool per camera,
/// left/right pairing per rig, frame sets assembled across rigs. Cameras that vanish are reopened
/// with back-off; counters and events in status() say what was lost.
class GigeSource : public FrameSource {
 public:
  /// Opens every camera (bounded by discovery_timeout_s) and starts acquisition.
  /// @throws romo::Error for a camera not found, a feature the camera refuses, or an image size
  ///   that disagrees with the rig's calibration; @p origin names the configuration in messages.
  GigeSource(const GigeConfig& config, const std::string& origin);
  ~GigeSource() override;

  std::optional<FrameSet> Next() override;
  const Calibration* calibration() const override;
  SourceStatus status() const override;
  std::vector<GigeCameraDiagnostics> diagnostics() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// Factory for the "gige" URI scheme: gige://<rig-config.yaml>[?stall_timeout_s=..&
/// discovery_timeout_s=..&lost_timeout_s=..] (query values override the file).
std::unique_ptr<FrameSource> OpenGigeSource(const Uri& uri);

/// A GigE Vision camera as Aravis discovers it (`romo cameras`).
struct GigeDeviceInfo {
  std::string id;
  std::string vendor;
  std::string model;
  std::string serial;
  std::string address;
  std::string protocol;
};
/// Broadcast discovery on every interface: on the vehicle network, or inside netns-run in tests.
std::vector<GigeDeviceInfo> DiscoverGigeCameras();

/// Serves images as emulated GigE Vision cameras (Aravis GV fake cameras with a fill pattern), one
/// IPv4 address each. All cameras share one frame clock: at each tick of 1/rate_hz every camera
/// sends frame (tick - first tick) of its sequence with device timestamp = tick time, so the two
/// cameras of a rig always send the same recorded instant with identical stamps.
class GigeEmulator {
 public:
  struct Camera {
    std::string address;  ///< e.g. 127.0.0.2 (must exist on an interface)
    std::string serial;   ///< at most 15 characters
    std::vector<Image> frames;  ///< same size and format each
  };
  /// @throws romo::Error for an empty or inconsistent frame list or a serial that is too long.
  GigeEmulator(std::vector<Camera> cameras, double rate_hz, bool loop);
  ~GigeEmulator();
  GigeEmulator(const GigeEmulator&) = delete;
  GigeEmulator& operator=(const GigeEmulator&) = delete;

  /// Frames handed to Aravis so far, per camera (in the order given).
  std::vector<std::uint64_t> frames_served() const;
  /// True once every camera has served its whole sequence (never with loop).
  bool finished() const;

  // Fault injection (hardware-in-loop tests, `romo gige-serve --packet-loss/--stall/...`).
  /// Every camera drops this fraction of its GVSP packets (0 to 1), as a lossy link would.
  /// @throws romo::Error for a ratio outside [0, 1].
  void SetPacketLoss(double ratio);
  /// A stalled camera keeps answering discovery and control (GVCP) but sends no frame (every
  /// GVSP packet dropped) until un-stalled. @throws romo::Error for an index out of range.
  void SetStalled(std::size_t camera, bool stalled);
  /// From the next tick on, every camera's device timestamps are shifted by @p offset_ns
  /// (negative: the camera clocks jump back, as after a clock reset). Cumulative.
  void ShiftStamps(std::int64_t offset_ns);
  /// Frames each camera sent while stalled (filled but never delivered).
  std::vector<std::uint64_t> frames_stalled() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// The GenICam pixel format the emulator serves for a romo image format (Mono8, Mono16, RGB8).
GigePixelFormat ServedFormat(PixelFormat format);

}  // namespace romo::drivers
