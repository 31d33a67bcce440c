#pragma once
/// Frame sources selected by URI: gige://rigs.yaml, log://file.lcmlog, rgbd://folder,
/// kinect://0, and schemes registered by other components (the simulator's sim://).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/drivers/uri.hpp"

namespace romo::drivers {

/// Per-camera counters: nothing dropped is hidden.
struct CameraCounters {
  std::string camera_id;
  std::uint64_t completed = 0;   ///< frames delivered intact
  std::uint64_t incomplete = 0;  ///< frames with missing packets or bad status
  std::uint64_t unpaired = 0;    ///< frames without a partner within the pairing tolerance
  std::uint64_t dropped = 0;     ///< frames lost (no buffer, queue overflow, sequence gaps)
  std::uint64_t reconnects = 0;  ///< times the camera was reopened after it disappeared
  std::int64_t gap_ns = 0;       ///< total time the camera was gone
};

struct SourceStatus {
  std::vector<CameraCounters> cameras;
  /// Human-readable events worth reporting (camera lost/back with gap, log truncated at offset).
  std::vector<std::string> events;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// Blocks until the next frame set; std::nullopt at the end of the stream.
  /// Expected run-time failures (a camera timing out) show in status(), not as exceptions.
  virtual std::optional<FrameSet> Next() = 0;
  /// The calibration the frames belong to, or nullptr where the source has none.
  virtual const Calibration* calibration() const { return nullptr; }
  virtual SourceStatus status() const { return {}; }
};

using SourceFactory = std::function<std::unique_ptr<FrameSource>(const Uri&)>;

/// Makes @p scheme available to OpenSource (components above drivers, e.g. the simulator).
void RegisterSourceScheme(const std::string& scheme, SourceFactory factory);

/// Opens the source named by @p uri.
/// @throws romo::Error for an unknown scheme (listing the known ones) or a source that cannot open.
std::unique_ptr<FrameSource> OpenSource(const std::string& uri);

}  // namespace romo::drivers
