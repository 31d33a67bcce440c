// LogWriter: LCM log files through lcm::LogFile, flushed per event, renamed into place on Close.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include "lcm_codec.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"

namespace romo::drivers {

class LogWriter::Impl {
 public:
  Impl(const std::string& path, ImageEncoding encoding)
      : path_(path), partial_path_(path + ".partial"), encoding_(encoding) {
    if (path.empty()) Fail("recording path is empty");
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

  void Write(const std::string& channel, std::int64_t stamp_ns,
             const std::vector<std::uint8_t>& data) {
    WriteBytes(channel, stamp_ns, data.data(), data.size());
  }

  void WriteBytes(const std::string& channel, std::int64_t stamp_ns, const void* data,
                  std::size_t size) {
    if (channel.empty()) Fail(path_ + ": event with an empty channel name");
    std::lock_guard<std::mutex> lock(mutex_);
    if (!log_) Fail(path_ + ": write after Close()");
    lcm::LogEvent event;
    event.eventnum = static_cast<std::int64_t>(events_);
    // LCM logs count time in microseconds.
    event.timestamp = stamp_ns / 1000;
    event.channel = channel;
    event.datalen = static_cast<std::int32_t>(size);
    event.data = const_cast<void*>(data);
    // Flushed per event so a crash loses at most the event being written.
    if (log_->writeEvent(&event) != 0 || std::fflush(log_->getFilePtr()) != 0) {
      Fail(partial_path_ + ": write failed after " + std::to_string(events_) +
           " events (disk full?): " + std::strerror(errno));
    }
    ++events_;
    bytes_ += 4 + 8 + 8 + 4 + 4 + channel.size() + size;
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
  const ImageEncoding encoding_;
  std::mutex mutex_;
  std::unique_ptr<lcm::LogFile> log_;
  std::uint64_t events_ = 0;
  std::uint64_t bytes_ = 0;
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
  for (const auto& [channel, data] : parts) impl_->Write(channel, frames.stamp_ns, data);
}

void LogWriter::WriteRaw(const std::string& channel, std::int64_t stamp_ns, const void* data,
                         std::size_t size) {
  impl_->WriteBytes(channel, stamp_ns, data, size);
}

void LogWriter::Close() { impl_->Close(); }

std::uint64_t LogWriter::events_written() const { return impl_->events_; }
std::uint64_t LogWriter::bytes_written() const { return impl_->bytes_; }
const std::string& LogWriter::path() const { return impl_->path_; }

}  // namespace romo::drivers
