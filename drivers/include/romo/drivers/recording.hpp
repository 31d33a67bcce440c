#pragma once
/// Recordings are LCM log files (lcm-logger / lcm-logplayer work on them). Channels:
///   ROMO_CALIBRATION        romo_lcm.calibration_t (YAML text), written first
///   ROMO_STEREO_RIG<k>      romo_lcm.stereo_frame_t
///   ROMO_RGBD               romo_lcm.rgbd_frame_t
///   ROMO_VEHICLE_STATE      romo_lcm.vehicle_state_t
///   ROMO_GNSS               romo_lcm.gnss_fix_t
/// Other channels (ground truth, outputs) pass through untouched as raw events.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/frames.hpp"

namespace romo::drivers {

enum class ImageEncoding : std::uint8_t { kRaw = 0, kPng = 1 };

inline constexpr char kCalibrationChannel[] = "ROMO_CALIBRATION";
inline constexpr char kStereoChannelPrefix[] = "ROMO_STEREO_RIG";
inline constexpr char kRgbdChannel[] = "ROMO_RGBD";
inline constexpr char kVehicleStateChannel[] = "ROMO_VEHICLE_STATE";
inline constexpr char kGnssChannel[] = "ROMO_GNSS";
/// "ROMO_STEREO_RIG<rig_id>".
std::string StereoChannel(int rig_id);
/// True for the channels that carry frame-set parts (stereo, RGB-D, vehicle state, GNSS).
bool IsFramePartChannel(const std::string& channel);

/// The LCM type of an encoded message from its 8-byte fingerprint ("romo_lcm.stereo_frame_t"),
/// or "unknown". romo_lcm sensor types are known; other modules add theirs with RegisterLcmType.
std::string LcmTypeName(const std::uint8_t* data, std::size_t size);
void RegisterLcmType(std::int64_t fingerprint, const std::string& type_name);

/// One raw log event.
struct LogEvent {
  std::int64_t timestamp_us = 0;  ///< the log's event time (LCM convention: microseconds)
  std::string channel;
  std::vector<std::uint8_t> data;
};

/// Writes a recording. The file is written as "<path>.partial" and renamed to <path> by Close()
/// (or the destructor), so a file being written is never mistaken for a complete one; every
/// completed event is flushed so a crash loses at most the event being written.
class LogWriter {
 public:
  /// Writes @p path.partial, renamed to @p path on Close. A @p path.partial already there was
  /// left by a writer that was killed: it is moved to <stem>.interrupted-<k>.lcmlog (see
  /// kept_interrupted()), never overwritten.
  /// @throws romo::Error when the file cannot be created or the old one not moved aside.
  explicit LogWriter(const std::string& path, ImageEncoding encoding = ImageEncoding::kRaw);
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  void WriteCalibration(const Calibration& calibration, std::int64_t stamp_ns);
  /// Writes every part of @p frames (stereo per rig, rgbd, vehicle state, GNSS).
  void Write(const FrameSet& frames);
  /// Writes an already-encoded LCM message (e.g. ground truth, outputs).
  void WriteRaw(const std::string& channel, std::int64_t stamp_ns, const void* data,
                std::size_t size);
  /// Flushes and renames the file into place. Idempotent.
  void Close();

  std::uint64_t events_written() const;
  std::uint64_t bytes_written() const;
  const std::string& path() const;
  /// Where an interrupted recording found at @p path.partial was kept; "" when there was none.
  const std::string& kept_interrupted() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

enum class Pacing { kAsFastAsPossible, kRealTime };

/// Reads a recording as a frame source (log://file.lcmlog?loop=1&pacing=realtime&seek_s=2.5).
/// A truncated log yields every complete event, then reports where it was cut in status().
class LogReader : public FrameSource {
 public:
  struct Options {
    bool loop = false;
    Pacing pacing = Pacing::kAsFastAsPossible;
    double seek_s = 0.0;  ///< start this far after the first event
  };
  /// @throws romo::Error when the file is missing or not an LCM log.
  explicit LogReader(const std::string& path, const Options& options);
  explicit LogReader(const std::string& path) : LogReader(path, Options{}) {}
  ~LogReader() override;

  std::optional<FrameSet> Next() override;
  const Calibration* calibration() const override;
  SourceStatus status() const override;

  /// Jumps to the first frame set at or after @p offset_s from the start of the log.
  void Seek(double offset_s);
  /// Raw events of channels that are not frame parts (ground truth, outputs) read while
  /// assembling the frame set returned by the last Next(): those written after the set's parts
  /// and before the next set's come with it. Cleared by each Next().
  const std::vector<LogEvent>& other_events() const;
  /// True when the file ended inside an event; truncation_offset() says where.
  bool truncated() const;
  std::int64_t truncation_offset() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// One GNSS fix as its ROMO_GNSS message (romo_lcm.gnss_fix_t), for processes that pass fixes
/// on a bus (a stereo worker to `romo fuse`).
std::vector<std::uint8_t> EncodeGnssMessage(const GnssFix& fix);
/// @throws romo::Error naming @p origin when the bytes are no gnss_fix_t or a valid fix is no
/// position (latitude beyond +-90 deg, longitude beyond +-180 deg, non-finite values).
GnssFix DecodeGnssMessage(const std::uint8_t* data, std::size_t size, const std::string& origin);

/// Reads every complete event of a log (for `romo info`, tests); stops at a truncated tail.
/// @param truncated_at set to the byte offset of the cut, or -1 when the file is complete.
std::vector<LogEvent> ReadAllEvents(const std::string& path, std::int64_t* truncated_at);

/// Streams every complete event of a log to @p visit without holding them all in memory.
/// @returns the byte offset where the file was cut or damaged, or -1 when it is complete.
/// @throws romo::Error when the file is missing or not an LCM log.
std::int64_t ScanEvents(const std::string& path, const std::function<void(const LogEvent&)>& visit);

/// The calibration carried by a ROMO_CALIBRATION event (e.g. from ReadAllEvents).
/// @throws romo::Error naming @p origin when it does not decode or validate.
Calibration CalibrationFromEvent(const LogEvent& event, const std::string& origin);

/// The frame_sequence carried by a frame-part event (stereo, RGB-D, vehicle state, GNSS), or
/// nullopt for other channels or too-short data.
std::optional<std::uint64_t> FrameSequenceOf(const LogEvent& event);

}  // namespace romo::drivers
