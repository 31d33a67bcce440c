// LogReader: a recording as a frame source. Frame sets are reassembled from their parts by
// frame_sequence; other channels pass through as raw events.
#include <chrono>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "lcm_codec.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
#include "romo_lcm/calibration_t.hpp"
#include "romo_lcm/gnss_fix_t.hpp"
#include "romo_lcm/image_t.hpp"
#include "romo_lcm/rgbd_frame_t.hpp"
#include "romo_lcm/stereo_frame_t.hpp"
#include "romo_lcm/vehicle_state_t.hpp"

namespace romo::drivers {
namespace {

using lcm_codec::EventFileReader;
using lcm_codec::ReadResult;

// The calibration is written first; if it is not among the first events it is not a header.
constexpr int kCalibrationScanEvents = 64;

struct TypeRegistry {
  std::mutex mutex;
  std::map<std::int64_t, std::string> names;
  TypeRegistry() {
    names[romo_lcm::image_t::getHash()] = "romo_lcm.image_t";
    names[romo_lcm::stereo_frame_t::getHash()] = "romo_lcm.stereo_frame_t";
    names[romo_lcm::rgbd_frame_t::getHash()] = "romo_lcm.rgbd_frame_t";
    names[romo_lcm::vehicle_state_t::getHash()] = "romo_lcm.vehicle_state_t";
    names[romo_lcm::gnss_fix_t::getHash()] = "romo_lcm.gnss_fix_t";
    names[romo_lcm::calibration_t::getHash()] = "romo_lcm.calibration_t";
  }
};

TypeRegistry& Types() {
  static TypeRegistry registry;
  return registry;
}

// The start of a corrupt region at byte 0 means the file never was an LCM log.
[[noreturn]] void NotALog(const lcm_codec::EventFileReader& reader) {
  Fail(reader.path() + ": not an LCM log file (" + reader.damage() + " at byte 0)");
}

}  // namespace

std::string StereoChannel(int rig_id) { return kStereoChannelPrefix + std::to_string(rig_id); }

bool IsFramePartChannel(const std::string& channel) {
  if (channel == kRgbdChannel || channel == kVehicleStateChannel || channel == kGnssChannel) {
    return true;
  }
  const std::size_t n = std::strlen(kStereoChannelPrefix);
  if (channel.size() <= n || channel.compare(0, n, kStereoChannelPrefix) != 0) return false;
  for (std::size_t i = n; i < channel.size(); ++i) {
    if (channel[i] < '0' || channel[i] > '9') return false;
  }
  return true;
}

std::string LcmTypeName(const std::uint8_t* data, std::size_t size) {
  if (size < 8) return "unknown";
  std::uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[i];  // LCM writes it big-endian
  auto& registry = Types();
  std::lock_guard<std::mutex> lock(registry.mutex);
  const auto it = registry.names.find(static_cast<std::int64_t>(hash));
  return it == registry.names.end() ? "unknown" : it->second;
}

void RegisterLcmType(std::int64_t fingerprint, const std::string& type_name) {
  auto& registry = Types();
  std::lock_guard<std::mutex> lock(registry.mutex);
  registry.names[fingerprint] = type_name;
}

std::int64_t ScanEvents(const std::string& path,
                        const std::function<void(const LogEvent&)>& visit) {
  EventFileReader reader(path);
  LogEvent event;
  for (;;) {
    const ReadResult result = reader.Next(&event);
    if (result == ReadResult::kEvent) {
      visit(event);
      continue;
    }
    if (result == ReadResult::kCorrupt && reader.offset() == 0) NotALog(reader);
    return result == ReadResult::kEnd ? -1 : reader.offset();
  }
}

std::vector<LogEvent> ReadAllEvents(const std::string& path, std::int64_t* truncated_at) {
  std::vector<LogEvent> events;
  const std::int64_t cut = ScanEvents(path, [&](const LogEvent& event) { events.push_back(event); });
  if (truncated_at != nullptr) *truncated_at = cut;
  return events;
}

std::optional<std::uint64_t> FrameSequenceOf(const LogEvent& event) {
  // Every part type starts with fingerprint (8 bytes), stamp_ns, frame_sequence (big-endian).
  if (!IsFramePartChannel(event.channel) || event.data.size() < 24) return std::nullopt;
  std::uint64_t value = 0;
  for (std::size_t i = 16; i < 24; ++i) value = (value << 8) | event.data[i];
  return value;
}

// Seek offsets beyond this are no recording's (30 years) and would overflow microseconds.
constexpr double kMaxSeekS = 1e9;

class LogReader::Impl {
 public:
  Impl(const std::string& path, const Options& options) : reader_(path), options_(options) {
    CheckSeekOffset(options.seek_s);
    LogEvent event;
    for (int i = 0; i < kCalibrationScanEvents; ++i) {
      const ReadResult result = reader_.Next(&event);
      if (result == ReadResult::kCorrupt && reader_.offset() == 0) NotALog(reader_);
      if (result != ReadResult::kEvent) break;
      if (i == 0) first_timestamp_us_ = event.timestamp_us;
      if (event.channel == kCalibrationChannel) {
        const std::string origin = path + ": " + kCalibrationChannel;
        calibration_ = Calibration::FromYaml(lcm_codec::DecodeCalibration(event.data, origin), origin);
        have_calibration_ = true;
        break;
      }
      if (IsFramePartChannel(event.channel)) break;
    }
    Rewind();
    // An open that delivers nothing would look like an empty recording.
    std::optional<double> last_frame_s;
    if (options.seek_s > 0 && !Seek(options.seek_s, &last_frame_s)) {
      std::ostringstream what;
      what << path << ": seek_s = " << options.seek_s << " s is past the recording's last frame";
      if (last_frame_s) what << " (at " << *last_frame_s << " s)";
      Fail(what.str());
    }
  }

  void Rewind() {
    reader_.SeekTo(0);
    pending_.reset();
    pace_started_ = false;
  }

  // The next event, from the look-ahead slot or the file; nullopt at the end or at damage.
  std::optional<LogEvent> NextEvent() {
    if (pending_) {
      std::optional<LogEvent> event = std::move(pending_);
      pending_.reset();
      return event;
    }
    LogEvent event;
    const ReadResult result = reader_.Next(&event);
    if (result == ReadResult::kEvent) return event;
    if (result != ReadResult::kEnd && !truncated_) {
      truncated_ = true;
      truncation_offset_ = reader_.offset();
      status_.events.push_back(reader_.path() + ": log " +
                               (result == ReadResult::kTruncated ? "truncated" : "corrupt") +
                               " at byte " + std::to_string(truncation_offset_) + " (" +
                               reader_.damage() + ") of " +
                               std::to_string(reader_.file_size()) +
                               "; every complete event before it was read");
    }
    return std::nullopt;
  }

  // Adds a frame-part event to @p set; false when the event could not be decoded (reported).
  bool AddPart(const LogEvent& event, FrameSet* set, std::uint64_t* sequence, bool* have_stamp) {
    const std::string origin = reader_.path() + ": " + event.channel + " event at " +
                               std::to_string(event.timestamp_us) + " us";
    try {
      if (event.channel == kRgbdChannel) {
        set->rgbd = lcm_codec::DecodeRgbd(event.data, origin, sequence);
      } else if (event.channel == kVehicleStateChannel) {
        set->vehicle = lcm_codec::DecodeVehicleState(event.data, origin, sequence);
      } else if (event.channel == kGnssChannel) {
        set->gnss = lcm_codec::DecodeGnss(event.data, origin, sequence);
      } else {
        std::int64_t stamp_ns = 0;
        set->stereo.push_back(lcm_codec::DecodeStereo(event.data, origin, &stamp_ns, sequence));
        set->stamp_ns = stamp_ns;
        *have_stamp = true;
      }
    } catch (const romo::Error& e) {
      ++undecodable_;
      status_.events.push_back(std::string("dropped: ") + e.what());
      return false;
    }
    return true;
  }

  std::optional<FrameSet> Next() {
    other_events_.clear();
    for (int attempt = 0; attempt < 2; ++attempt) {
      std::optional<FrameSet> set = Assemble();
      if (set) {
        Pace(*set);
        return set;
      }
      if (!options_.loop || sets_delivered_ == 0) return std::nullopt;
      Rewind();
    }
    return std::nullopt;
  }

  std::optional<FrameSet> Assemble() {
    FrameSet set;
    bool started = false;
    bool have_stamp = false;
    std::uint64_t set_sequence = 0;
    std::int64_t first_part_us = 0;
    while (std::optional<LogEvent> event = NextEvent()) {
      if (event->channel == kCalibrationChannel) {
        UpdateCalibration(*event);
        continue;
      }
      if (!IsFramePartChannel(event->channel)) {
        other_events_.push_back(std::move(*event));
        continue;
      }
      const std::optional<std::uint64_t> sequence = FrameSequenceOf(*event);
      if (started && sequence && *sequence != set_sequence) {
        pending_ = std::move(event);  // first part of the next set
        break;
      }
      std::uint64_t decoded_sequence = 0;
      if (!AddPart(*event, &set, &decoded_sequence, &have_stamp)) continue;
      if (!started) {
        started = true;
        set_sequence = decoded_sequence;
        first_part_us = event->timestamp_us;
      }
    }
    if (!started) return std::nullopt;
    set.sequence = set_sequence;
    if (!have_stamp) set.stamp_ns = first_part_us * 1000;  // event time, microsecond precision
    if (sets_delivered_ > 0 && set_sequence > last_sequence_ + 1) {
      dropped_ += set_sequence - last_sequence_ - 1;
    }
    last_sequence_ = set_sequence;
    ++sets_delivered_;
    last_event_us_ = first_part_us;
    return set;
  }

  void UpdateCalibration(const LogEvent& event) {
    const std::string origin = reader_.path() + ": " + kCalibrationChannel;
    try {
      calibration_ = Calibration::FromYaml(lcm_codec::DecodeCalibration(event.data, origin), origin);
      have_calibration_ = true;
    } catch (const romo::Error& e) {
      status_.events.push_back(std::string("ignored calibration: ") + e.what());
    }
  }

  void Pace(const FrameSet&) {
    if (options_.pacing != Pacing::kRealTime) return;
    const auto now = std::chrono::steady_clock::now();
    if (!pace_started_) {
      pace_started_ = true;
      pace_wall_start_ = now;
      pace_log_start_us_ = last_event_us_;
      return;
    }
    const auto due = pace_wall_start_ + std::chrono::microseconds(last_event_us_ - pace_log_start_us_);
    if (due > now) std::this_thread::sleep_until(due);
  }

  void CheckSeekOffset(double offset_s) const {
    if (!(offset_s >= 0 && offset_s <= kMaxSeekS)) {
      Fail(reader_.path() + ": seek offset " + std::to_string(offset_s) + " s must be within 0..1e9 s");
    }
  }

  // Positions at the first frame part at or after @p offset_s; false (and at the end) when the
  // recording has none, with the last frame's offset in @p last_frame_s.
  bool Seek(double offset_s, std::optional<double>* last_frame_s = nullptr) {
    CheckSeekOffset(offset_s);
    Rewind();
    const std::int64_t target_us = first_timestamp_us_ + static_cast<std::int64_t>(offset_s * 1e6);
    while (std::optional<LogEvent> event = NextEvent()) {
      if (event->channel == kCalibrationChannel) {
        UpdateCalibration(*event);
      } else if (IsFramePartChannel(event->channel)) {
        if (event->timestamp_us >= target_us) {
          pending_ = std::move(event);
          return true;
        }
        if (last_frame_s) *last_frame_s = 1e-6 * static_cast<double>(event->timestamp_us - first_timestamp_us_);
      }
    }
    return false;
  }

  SourceStatus Status() const {
    SourceStatus status = status_;
    CameraCounters counters;
    counters.camera_id = "log:" + reader_.path();
    counters.completed = sets_delivered_;
    counters.incomplete = undecodable_;
    counters.dropped = dropped_;
    status.cameras.push_back(counters);
    return status;
  }

  EventFileReader reader_;
  Options options_;
  Calibration calibration_;
  bool have_calibration_ = false;
  std::int64_t first_timestamp_us_ = 0;
  std::optional<LogEvent> pending_;
  std::vector<LogEvent> other_events_;
  SourceStatus status_;
  bool truncated_ = false;
  std::int64_t truncation_offset_ = -1;
  std::uint64_t sets_delivered_ = 0;
  std::uint64_t last_sequence_ = 0;
  std::uint64_t dropped_ = 0;
  std::uint64_t undecodable_ = 0;
  std::int64_t last_event_us_ = 0;
  bool pace_started_ = false;
  std::chrono::steady_clock::time_point pace_wall_start_;
  std::int64_t pace_log_start_us_ = 0;
};

LogReader::LogReader(const std::string& path, const Options& options)
    : impl_(std::make_unique<Impl>(path, options)) {}

LogReader::~LogReader() = default;

std::optional<FrameSet> LogReader::Next() { return impl_->Next(); }

const Calibration* LogReader::calibration() const {
  return impl_->have_calibration_ ? &impl_->calibration_ : nullptr;
}

SourceStatus LogReader::status() const { return impl_->Status(); }

void LogReader::Seek(double offset_s) { impl_->Seek(offset_s); }

const std::vector<LogEvent>& LogReader::other_events() const { return impl_->other_events_; }

bool LogReader::truncated() const { return impl_->truncated_; }

std::int64_t LogReader::truncation_offset() const { return impl_->truncation_offset_; }

std::unique_ptr<FrameSource> OpenLogSource(const Uri& uri) {
  LogReader::Options options;
  for (const auto& [key, value] : uri.query) {
    if (key != "loop" && key != "pacing" && key != "seek_s") {
      Fail(uri.ToString() + ": unknown option '" + key + "' (log:// takes loop, pacing, seek_s)");
    }
  }
  if (const auto loop = uri.Get("loop")) {
    if (*loop == "1" || *loop == "true") {
      options.loop = true;
    } else if (*loop != "0" && *loop != "false") {
      Fail(uri.ToString() + ": loop = '" + *loop + "' must be 0, 1, true or false");
    }
  }
  if (const auto pacing = uri.Get("pacing")) {
    if (*pacing == "realtime") {
      options.pacing = Pacing::kRealTime;
    } else if (*pacing != "fast") {
      Fail(uri.ToString() + ": pacing = '" + *pacing + "' must be realtime or fast");
    }
  }
  if (const auto seek = uri.GetDouble("seek_s", 0.0, kMaxSeekS)) options.seek_s = *seek;
  if (uri.path.empty()) Fail(uri.ToString() + ": no file named (log://FILE.lcmlog)");
  return std::make_unique<LogReader>(uri.path, options);
}

Calibration CalibrationFromEvent(const LogEvent& event, const std::string& origin) {
  return Calibration::FromYaml(lcm_codec::DecodeCalibration(event.data, origin), origin);
}

}  // namespace romo::drivers
