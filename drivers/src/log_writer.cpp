// LogWriter: LCM log files through lcm::LogFile, flushed per event, renamed into place on Close.
// A failed write (disk full) cuts the file back to the last whole frame set and makes later
// writes throw; Close() still renames it, so the recording keeps every complete frame set.
// A .partial left by a writer that was killed is moved aside, never overwritten.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdio_ext.h>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include "lcm_codec.hpp"
#include "romo/core/check.hpp"
#include "romo/core/partial_file.hpp"
#include "romo/drivers/recording.hpp"

namespace romo::drivers {

class LogWriter::Impl {
 public:
  Impl(const std::string& path, ImageEncoding encoding)
      : path_(path), partial_path_(path + ".partial"), encoding_(encoding) {
    if (path.empty()) Fail("recording path is empty");
    kept_interrupted_ = KeepInterruptedPartial(path_);
    log_ = std::make_unique<lcm::LogFile>(partial_path_, "w");
    if (!log_->good()) {
      Fail(partial_path_ + ": cannot create recording: " + std::strerror(errno));
    }
  }

  ~Impl() {
    try {
      Close();
    } catch (const std::exception& e) {
      // A destructor must not throw; the .partial file keeps every completed event.
      std::fprintf(stderr, "romo: closing %s failed: %s\n", path_.c_str(), e.what());
    }
  }

  struct Part {
    std::string channel;
    const void* data = nullptr;
    std::size_t size = 0;
  };

  void Write(const std::string& channel, std::int64_t stamp_ns,
             const std::vector<std::uint8_t>& data) {
    WriteBytes(channel, stamp_ns, data.data(), data.size());
  }

  void WriteBytes(const std::string& channel, std::int64_t stamp_ns, const void* data,
                  std::size_t size) {
    WriteAll({Part{channel, data, size}}, stamp_ns);
  }

  // Writes @p parts as one unit: when one fails (disk full), the file is cut back to where the
  // unit started, so it holds only whole units (frame sets) and stays a valid log; the writer
  // then refuses further writes but Close() still renames it into place.
  void WriteAll(const std::vector<Part>& parts, std::int64_t stamp_ns) {
    for (const Part& part : parts) {
      if (part.channel.empty()) Fail(path_ + ": event with an empty channel name");
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!log_) Fail(path_ + ": write after Close()");
    if (!failure_.empty()) Fail(failure_);
    const std::uint64_t start_events = events_;
    const std::uint64_t start_bytes = bytes_;
    for (const Part& part : parts) {
      const int error = WriteEvent(part.channel, stamp_ns, part.data, part.size);
      if (error == 0) continue;
      const bool cut = CutBack(start_bytes);
      events_ = start_events;
      bytes_ = start_bytes;
      failure_ = partial_path_ + ": write failed after " + std::to_string(events_) + " complete events (" +
                 std::to_string(bytes_) + " bytes)" + (error == ENOSPC ? " - disk full" : "") + ": " +
                 std::strerror(error) +
                 (cut ? "; the recording keeps every complete event before it"
                      : "; the file could not be cut back, its last event is incomplete");
      Fail(failure_);
    }
  }

  // One event, flushed so a crash loses at most the event being written. Returns 0 or errno.
  int WriteEvent(const std::string& channel, std::int64_t stamp_ns, const void* data, std::size_t size) {
    lcm::LogEvent event;
    event.eventnum = static_cast<std::int64_t>(events_);
    // LCM logs count time in microseconds.
    event.timestamp = stamp_ns / 1000;
    event.channel = channel;
    event.datalen = static_cast<std::int32_t>(size);
    event.data = const_cast<void*>(data);
    errno = 0;
    if (log_->writeEvent(&event) != 0 || std::fflush(log_->getFilePtr()) != 0) {
      return errno != 0 ? errno : EIO;
    }
    ++events_;
    // An LCM log event: sync word, event number, timestamp, channel length, data length, channel, data.
    bytes_ += 4 + 8 + 8 + 4 + 4 + channel.size() + size;
    return 0;
  }

  // Drops what stdio still buffers and truncates the file to @p bytes (frees the space too).
  bool CutBack(std::uint64_t bytes) {
    std::FILE* file = log_->getFilePtr();
    __fpurge(file);
    return ::ftruncate(::fileno(file), static_cast<off_t>(bytes)) == 0 &&
           std::fseek(file, static_cast<long>(bytes), SEEK_SET) == 0;
  }

  void Close() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!log_) return;
    std::FILE* file = log_->getFilePtr();
    const bool synced = std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
    log_.reset();  // closes the file
    if (!synced) Fail(partial_path_ + ": flushing failed: " + std::strerror(errno));
    if (std::rename(partial_path_.c_str(), path_.c_str()) != 0) {
      Fail(partial_path_ + ": cannot rename to " + path_ + ": " + std::strerror(errno));
    }
  }

  const std::string path_;
  const std::string partial_path_;
  std::string kept_interrupted_;
  const ImageEncoding encoding_;
  std::mutex mutex_;
  std::unique_ptr<lcm::LogFile> log_;
  std::uint64_t events_ = 0;
  std::uint64_t bytes_ = 0;
  std::string failure_;  // set by a failed write: later writes fail with it
};

LogWriter::LogWriter(const std::string& path, ImageEncoding encoding)
    : impl_(std::make_unique<Impl>(path, encoding)) {}

LogWriter::~LogWriter() = default;

void LogWriter::WriteCalibration(const Calibration& calibration, std::int64_t stamp_ns) {
  calibration.Validate("calibration written to " + impl_->path_);
  impl_->Write(kCalibrationChannel, stamp_ns,
               lcm_codec::EncodeCalibration(calibration.ToYaml(), stamp_ns));
}

void LogWriter::Write(const FrameSet& frames) {
  // Encode everything first so a bad part throws before any part of the set is written.
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> parts;
  for (const StereoFrame& stereo : frames.stereo) {
    if (stereo.rig_id < 0) Fail(impl_->path_ + ": stereo frame with rig id " + std::to_string(stereo.rig_id));
    parts.emplace_back(StereoChannel(stereo.rig_id),
                       lcm_codec::EncodeStereo(stereo, frames.stamp_ns, frames.sequence,
                                               impl_->encoding_));
  }
  if (frames.rgbd) {
    parts.emplace_back(kRgbdChannel,
                       lcm_codec::EncodeRgbd(*frames.rgbd, frames.sequence, impl_->encoding_));
  }
  if (frames.vehicle) {
    parts.emplace_back(kVehicleStateChannel,
                       lcm_codec::EncodeVehicleState(*frames.vehicle, frames.sequence));
  }
  if (frames.gnss) {
    parts.emplace_back(kGnssChannel, lcm_codec::EncodeGnss(*frames.gnss, frames.sequence));
  }
  // A frame set goes in whole or not at all (see WriteAll).
  std::vector<Impl::Part> events;
  for (const auto& [channel, data] : parts) events.push_back({channel, data.data(), data.size()});
  impl_->WriteAll(events, frames.stamp_ns);
}

void LogWriter::WriteRaw(const std::string& channel, std::int64_t stamp_ns, const void* data,
                         std::size_t size) {
  impl_->WriteBytes(channel, stamp_ns, data, size);
}

void LogWriter::Close() { impl_->Close(); }

std::uint64_t LogWriter::events_written() const { return impl_->events_; }
std::uint64_t LogWriter::bytes_written() const { return impl_->bytes_; }
const std::string& LogWriter::path() const { return impl_->path_; }

const std::string& LogWriter::kept_interrupted() const { return impl_->kept_interrupted_; }

}  // namespace romo::drivers
