// `romo record --source URI --out FILE.lcmlog [--frames N] [--png] [--status-lcm-url URL]`: any
// frame source to an LCM log, optionally publishing a perception status (camera losses, events,
// write failures) after every frame set, and twice a second while a live source is silent, so
// faults show on the bus while recording.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/gige.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/planning_iface/lcm_bus.hpp"
#include "romo/planning_iface/messages.hpp"

namespace romo::tools {
namespace {

std::atomic<bool> g_stop{false};

extern "C" void OnStopSignal(int) { g_stop = true; }

struct RecordOptions {
  std::string source;
  std::string out;
  std::uint64_t frames = 0;
  bool png = false;
  std::string status_lcm_url;
};

void PrintSourceEvents(const drivers::FrameSource& source) {
  const drivers::SourceStatus status = source.status();
  for (const auto& event : status.events) std::fprintf(stderr, "romo record: %s\n", event.c_str());
  for (const auto& cam : status.cameras) {
    if (cam.incomplete + cam.unpaired + cam.dropped + cam.reconnects == 0) continue;
    std::fprintf(stderr,
                 "romo record: %s: %llu completed, %llu incomplete, %llu unpaired, %llu dropped, "
                 "%llu reconnects\n",
                 cam.camera_id.c_str(), static_cast<unsigned long long>(cam.completed),
                 static_cast<unsigned long long>(cam.incomplete),
                 static_cast<unsigned long long>(cam.unpaired),
                 static_cast<unsigned long long>(cam.dropped),
                 static_cast<unsigned long long>(cam.reconnects));
  }
}

// The recorder's perception status: per rig the frame sets it was in, frames_processed = sets
// written, frames_dropped = camera frames that never reached the file (incomplete, unpaired,
// dropped), events = source events and the recorder's own (stamps going back, write failures),
// each published once. Thread-safe: a heartbeat publishes while the source is silent.
class StatusPublisher {
 public:
  using Clock = std::chrono::steady_clock;

  explicit StatusPublisher(const std::string& url) {
    if (!url.empty()) bus_ = std::make_unique<planning_iface::LcmBus>(url);
  }

  bool enabled() const { return bus_ != nullptr; }

  void AddEvent(const std::string& event) {
    std::lock_guard<std::mutex> lock(mutex_);
    own_events_.push_back(event);
  }

  void CountSet(const drivers::FrameSet& frames) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_stamp_ns_ = frames.stamp_ns;
    last_sequence_ = static_cast<std::int64_t>(frames.sequence);
    present_.clear();
    for (const auto& stereo : frames.stereo) {
      ++rig_frames_[stereo.rig_id];
      present_[stereo.rig_id] = true;
    }
    ++sets_;
  }

  void Publish(const drivers::FrameSource& source, double write_ms) {
    if (!bus_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    PublishLocked(source, write_ms);
  }

  /// Publishes (no new set, same counters, new events) when nothing went out for @p quiet.
  void PublishIfQuiet(const drivers::FrameSource& source, Clock::duration quiet) {
    if (!bus_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (Clock::now() - last_publish_ >= quiet) PublishLocked(source, 0.0);
  }

 private:
  planning_iface::PerceptionStatus Build(const drivers::SourceStatus& source, double write_ms) {
    planning_iface::PerceptionStatus status;
    status.stamp_ns = last_stamp_ns_;
    status.frame_sequence = last_sequence_;
    for (const auto& [rig_id, frames] : rig_frames_) {
      planning_iface::RigStatus rig;
      rig.rig_id = rig_id;
      rig.present = present_.count(rig_id) > 0;
      rig.frames = frames;
      rig.dropped = sets_ - frames;  // sets recorded without this rig
      status.rigs.push_back(rig);
    }
    status.stages.push_back({"write", write_ms});
    status.total_latency_ms = write_ms;
    status.frames_processed = sets_;
    for (const auto& camera : source.cameras) {
      status.frames_dropped += static_cast<std::int64_t>(camera.incomplete + camera.unpaired + camera.dropped);
    }
    for (std::size_t i = source_events_published_; i < source.events.size(); ++i) {
      status.events.push_back(source.events[i]);
    }
    source_events_published_ = source.events.size();
    for (auto& event : own_events_) status.events.push_back(std::move(event));
    own_events_.clear();
    return status;
  }

  void PublishLocked(const drivers::FrameSource& source, double write_ms) {
    last_publish_ = Clock::now();
    const auto status = Build(source.status(), write_ms);
    try {
      bus_->Publish(planning_iface::kPerceptionStatusChannel, planning_iface::Encode(status));
    } catch (const Error& e) {
      // Status is best effort: a bus problem must not stop the recording.
      if (!publish_failed_) std::fprintf(stderr, "romo record: publishing the status failed: %s\n", e.what());
      publish_failed_ = true;
    }
  }

  std::unique_ptr<planning_iface::LcmBus> bus_;
  std::mutex mutex_;
  Clock::time_point last_publish_ = Clock::now();
  std::map<int, std::int64_t> rig_frames_;
  std::map<int, bool> present_;
  std::int64_t sets_ = 0;
  std::int64_t last_stamp_ns_ = 0;
  std::int64_t last_sequence_ = 0;
  std::size_t source_events_published_ = 0;
  std::vector<std::string> own_events_;
  bool publish_failed_ = false;
};

// While the source is silent (a stalled camera holds Next() up to stall_timeout_s) the status
// still goes out every kQuiet, so a stall shows while it lasts, not only once frames are back.
// Only for the live GigE source: its status() may be called while Next() blocks.
class StatusHeartbeat {
 public:
  static constexpr std::chrono::milliseconds kQuiet{500};

  StatusHeartbeat(StatusPublisher* status, const drivers::FrameSource& source) {
    if (!status->enabled() || dynamic_cast<const drivers::GigeSource*>(&source) == nullptr) return;
    thread_ = std::thread([this, status, &source] {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!stop_) {
        wake_.wait_for(lock, std::chrono::milliseconds(100));
        if (!stop_) status->PublishIfQuiet(source, kQuiet);
      }
    });
  }
  ~StatusHeartbeat() { Stop(); }
  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

void Record(const RecordOptions& options) {
  using Clock = std::chrono::steady_clock;
  // SIGINT/SIGTERM stop the loop; the writer then closes and renames the file as usual.
  // Installed first: a signal while the source opens must not kill the process either.
  g_stop = false;
  auto* old_int = std::signal(SIGINT, OnStopSignal);
  auto* old_term = std::signal(SIGTERM, OnStopSignal);
  StatusPublisher status(options.status_lcm_url);
  // Opening errors (bad URI, missing file, no camera) are bad input: romo::Error -> exit 2.
  std::unique_ptr<drivers::FrameSource> source = drivers::OpenSource(options.source);
  drivers::LogWriter writer(options.out,
                            options.png ? drivers::ImageEncoding::kPng : drivers::ImageEncoding::kRaw);
  if (!writer.kept_interrupted().empty()) {
    const std::string event = "record: " + options.out + ".partial was left by an interrupted recording; kept as " +
                              writer.kept_interrupted();
    std::fprintf(stderr, "romo %s\n", event.c_str());
    status.AddEvent(event);
  }

  StatusHeartbeat heartbeat(&status, *source);
  Progress progress("record", options.frames);
  std::uint64_t count = 0;
  bool calibration_written = false;
  std::optional<std::string> failure;
  bool write_failed = false;
  std::optional<std::int64_t> last_stamp;
  std::uint64_t stamps_back = 0;
  while (!g_stop && (options.frames == 0 || count < options.frames)) {
    std::optional<drivers::FrameSet> frames;
    try {
      frames = source->Next();
      if (!frames) break;
    } catch (const std::exception& e) {
      failure = std::string("source failed: ") + e.what();
      break;
    }
    if (last_stamp && frames->stamp_ns < *last_stamp) {
      // Kept as recorded (nothing is lost); consumers that need order (replay) skip and count.
      ++stamps_back;
      status.AddEvent("record: frame set " + std::to_string(count) + " stamp went back by " +
                      std::to_string(static_cast<double>(*last_stamp - frames->stamp_ns) * 1e-9) +
                      " s (kept; jump " + std::to_string(stamps_back) + ")");
    }
    last_stamp = frames->stamp_ns;
    const auto write_start = Clock::now();
    try {
      if (!calibration_written) {
        // Written first, stamped like the first frame set so seek offsets start there.
        if (const auto* calibration = source->calibration()) {
          writer.WriteCalibration(*calibration, frames->stamp_ns);
        }
        calibration_written = true;
      }
      writer.Write(*frames);
    } catch (const std::exception& e) {
      failure = std::string("writing the recording failed: ") + e.what();
      write_failed = true;
      break;
    }
    ++count;
    status.CountSet(*frames);
    // Published after the set is on disk: a status saying N sets means N sets are in the file.
    status.Publish(*source, std::chrono::duration<double, std::milli>(Clock::now() - write_start).count());
    progress.Update(count, std::to_string(writer.bytes_written() / (1024 * 1024)) + " MB");
  }
  if (!calibration_written && !write_failed && source->calibration() != nullptr) {
    try {
      writer.WriteCalibration(*source->calibration(), 0);
    } catch (const std::exception& e) {
      failure = std::string("writing the recording failed: ") + e.what();
      write_failed = true;
    }
  }
  heartbeat.Stop();
  progress.Finish(std::to_string(writer.bytes_written() / (1024 * 1024)) + " MB");
  writer.Close();
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);
  PrintSourceEvents(*source);
  std::printf("recorded %llu frame sets (%llu events, %.1f MB) to %s%s\n",
              static_cast<unsigned long long>(count),
              static_cast<unsigned long long>(writer.events_written()),
              static_cast<double>(writer.bytes_written()) / 1e6, options.out.c_str(),
              g_stop ? " (interrupted)" : "");
  if (stamps_back > 0) {
    std::fprintf(stderr, "romo record: frame set stamps went back %llu times (all sets kept)\n",
                 static_cast<unsigned long long>(stamps_back));
  }
  if (failure) {
    const std::string message = "romo record: " + *failure + " (stopped after " + std::to_string(count) +
                                " frame sets; all " + std::to_string(count) + " kept in " + options.out + ")";
    status.AddEvent(message);
    status.Publish(*source, 0.0);
    std::fprintf(stderr, "%s\n", message.c_str());
    throw CLI::RuntimeError(kExitRuntimeFailure);
  }
  status.Publish(*source, 0.0);
}

void Register(CLI::App& root) {
  auto options = std::make_shared<RecordOptions>();
  auto* command = root.add_subcommand(
      "record", "Record a frame source (gige://, log://, rgbd://, kinect://, sim://) to an LCM log");
  command->add_option("--source", options->source, "Source URI, e.g. rgbd:///data/tum")->required();
  command->add_option("--out", options->out, "Output LCM log file (.lcmlog)")->required();
  command->add_option("--frames", options->frames, "Stop after N frame sets (0 = until the end)");
  command->add_flag("--png", options->png, "Store images as lossless PNG instead of raw");
  command->add_option("--status-lcm-url", options->status_lcm_url,
                      "Publish a perception status (ROMO_PERCEPTION_STATUS: sets written, camera "
                      "frames lost, events) on this LCM URL after every frame set (gige://: also every "
                      "0.5 s while no set comes)");
  command->callback([options] { Record(*options); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
