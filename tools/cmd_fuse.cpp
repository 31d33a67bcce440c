// `romo fuse --lcm-url URL`: mapping, objects and planning on the rig clouds that stereo workers
// publish. Frames are assembled by stamp; a rig that has not arrived within --timeout-ms is
// reported missing (sector not covered) and the frame goes on without it. Malformed messages
// are counted and reported, never fatal. GNSS fixes on ROMO_GNSS (the receiver's driver, or a
// worker with --publish-gnss) give the geodetic outputs; each frame takes the newest fix at most
// --gnss-max-age-ms older than it, and bridges gaps by odometry like a single process.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <functional>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "cli/picture_options.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/pipeline/outputs.hpp"
#include "romo/pipeline/pipeline.hpp"
#include "romo/planning_iface/lcm_bus.hpp"
#include "romo/planning_iface/messages.hpp"

namespace romo::tools {
namespace {

struct FuseOptions {
  std::string lcm_url;
  std::string calib;
  std::string out_dir;
  int timeout_ms = 500;
  double idle_exit_s = 10.0;
  long long frames = 0;
  pipeline::OutputOptions pictures;  ///< --no-pictures, --picture-span (the rest comes from the fields above)
  // A full-resolution rig cloud (782 x 582 points at 8 bytes) is 3.6 MB; anything far larger is
  // refused before decoding so a bad or hostile sender cannot make fuse allocate without bound.
  std::size_t max_message_bytes = 8u << 20;
  // Kernel UDP receive buffer asked for on udpm:// (LCM's recv_buf_size) unless the URL sets one.
  // The default 208 kB holds less than one half-resolution frame of six rig clouds: on a busy
  // machine LCM's reader thread falls behind a burst and the kernel drops fragments unseen
  // (measured: 5 of 8 frames arrived, each with 1 of 6 rigs). 32 MB holds a few full-resolution
  // frames (6 x 3.6 MB); the kernel caps it at net.core.rmem_max.
  long long recv_buf_bytes = 32ll << 20;
  int gnss_max_age_ms = 200;
};

// @p url with recv_buf_size=@p bytes added when it is udpm:// and sets none.
std::string WithReceiveBuffer(const std::string& url, long long bytes) {
  if (url.rfind("udpm://", 0) != 0 || url.find("recv_buf_size=") != std::string::npos || bytes <= 0) return url;
  return url + (url.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=" + std::to_string(bytes);
}

// net.core.rmem_max (the most SO_RCVBUF may ask for), or -1 when unreadable (not Linux).
long long KernelReceiveBufferMax() {
  std::ifstream in("/proc/sys/net/core/rmem_max");
  long long v = -1;
  return (in >> v) ? v : -1;
}

// One message off the bus. Oversized ones keep only their size (never copied), and so do the
// ones that found the queue full (overflow).
struct Received {
  std::string channel;
  std::size_t size = 0;
  std::vector<std::uint8_t> data;
  bool overflow = false;
};

// Takes messages off LCM on a thread of its own, so none is lost while a frame is being fused.
// Bounded by bytes; what does not fit is counted, not silently lost.
//
// LCM's own queue between its reader thread and this one holds 30 messages by default and drops
// the rest unseen: on a busy machine this thread can wait for a core while a burst of a few
// frames (6 rigs x (cloud + faults)) arrives. Found in CI: a frame's six clouds lost after four
// frames' bursts. 512 is 85 frames of six rigs; this thread empties it as soon as it runs.
constexpr int kLcmQueueCapacity = 512;
class Inbox {
 public:
  Inbox(const std::string& url, std::size_t max_message_bytes, std::size_t max_queued_bytes)
      : bus_(url), max_message_bytes_(max_message_bytes), max_queued_bytes_(max_queued_bytes) {
    auto receive = [this](const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t) {
      Received m;
      m.channel = channel;
      m.size = size;
      if (size <= max_message_bytes_) m.data.assign(data, data + size);
      std::lock_guard<std::mutex> lock(mutex_);
      if (queued_bytes_ + m.data.size() > max_queued_bytes_) {
        m.overflow = true;
        m.data.clear();
      }
      queued_bytes_ += m.data.size();
      queue_.push_back(std::move(m));
      ready_.notify_one();
    };
    bus_.Subscribe(std::string(planning_iface::kRigCloudChannelPrefix) + "[0-9]+", receive, kLcmQueueCapacity);
    bus_.Subscribe(drivers::kGnssChannel, receive, kLcmQueueCapacity);
    thread_ = std::thread([this] {
      try {
        while (!stop_) bus_.Handle(50);
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = e.what();
        ready_.notify_one();
      }
    });
  }
  ~Inbox() {
    stop_ = true;
    thread_.join();
  }
  Inbox(const Inbox&) = delete;
  Inbox& operator=(const Inbox&) = delete;

  /// Everything received so far, waiting up to @p timeout_ms for the first message.
  /// @throws romo::Error when LCM failed on the receiving thread.
  std::deque<Received> Take(int timeout_ms) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                    [this] { return !queue_.empty() || !error_.empty(); });
    if (!error_.empty()) Fail("fuse: " + error_);
    std::deque<Received> out;
    out.swap(queue_);
    queued_bytes_ = 0;
    return out;
  }

 private:
  planning_iface::LcmBus bus_;
  const std::size_t max_message_bytes_, max_queued_bytes_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Received> queue_;
  std::size_t queued_bytes_ = 0;
  std::string error_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// The pipeline, made once the first rig cloud says what size the workers' images are (its
// defaults depend on it: full-resolution images take L-shape headings). Faults counted before
// reach it when it is made.
class FusePipeline {
 public:
  /// @throws romo::Error as Pipeline's constructor does, at once (not at the first cloud).
  FusePipeline(const drivers::Calibration& calibration, pipeline::PipelineParams fallback)
      : calibration_(calibration), fallback_(std::move(fallback)) {
    const pipeline::Pipeline probe(calibration_, fallback_);
  }

  bool made() const { return pipe_ != nullptr; }
  /// Makes it for clouds of @p image_width_px wide images (0: not said, the fallback params).
  pipeline::Pipeline& Make(int image_width_px) {
    if (pipe_) return *pipe_;
    const int threads = fallback_.threads;
    pipe_ = std::make_unique<pipeline::Pipeline>(
        calibration_, image_width_px > 0 ? pipeline::PipelineParams::ForImageWidth(image_width_px, threads) : fallback_);
    image_width_px_ = image_width_px;
    for (const auto& fault : early_) fault(*pipe_);
    early_.clear();
    return *pipe_;
  }
  pipeline::Pipeline& Get() { return Make(0); }
  int image_width_px() const { return image_width_px_; }

  void CountMalformed() { Do([](pipeline::Pipeline& p) { p.CountMalformed(); }); }
  void CountDropped(int rig_id) { Do([rig_id](pipeline::Pipeline& p) { p.CountDropped(rig_id); }); }
  void ReportEvent(const std::string& event) { Do([event](pipeline::Pipeline& p) { p.ReportEvent(event); }); }

 private:
  template <typename F>
  void Do(F f) {
    if (pipe_) {
      f(*pipe_);
    } else {
      early_.emplace_back(std::move(f));
    }
  }

  const drivers::Calibration& calibration_;
  const pipeline::PipelineParams fallback_;
  std::unique_ptr<pipeline::Pipeline> pipe_;
  int image_width_px_ = 0;
  std::vector<std::function<void(pipeline::Pipeline&)>> early_;
};

void Fuse(const FuseOptions& o) {
  using Clock = std::chrono::steady_clock;
  const drivers::Calibration calibration =
      drivers::Calibration::Load(o.calib.empty() ? drivers::SampleCalibrationPath() : o.calib);
  // Workers say their image size in each cloud; when they do not, a calibration given by --calib
  // tells it, and the sample one (full-size, while workers may send clouds of any size) does not:
  // the plain defaults are half resolution's, as `romo replay` takes them for half-size recordings.
  FusePipeline pipe(calibration,
                    o.calib.empty() ? pipeline::PipelineParams{} : pipeline::PipelineParams::ForCalibration(calibration, pipeline::PipelineParams{}.threads));
  pipeline::OutputOptions out = o.pictures;
  out.out_dir = o.out_dir;
  out.lcm_url = o.lcm_url;
  out.log_inputs = false;
  pipeline::OutputSink sink(calibration, out);
  // Recent fixes by stamp (a few seconds at any GNSS rate); the pipeline reports frames without one.
  std::map<std::int64_t, drivers::GnssFix> fixes;
  constexpr std::size_t kFixesKept = 256;
  long long frames_with_fix = 0;

  struct Pending {
    Clock::time_point first_arrival;
    std::int64_t sequence = 0;
    std::map<int, pipeline::RigInput> rigs;
    std::optional<drivers::VehicleState> vehicle;
  };
  std::map<std::int64_t, Pending> pending;  // by stamp
  std::int64_t last_done_stamp = -1;
  // Newest stamp each rig has delivered: a worker publishes in stamp order, so a rig that has
  // sent a newer frame will not send an older one it skipped (no need to wait out the timeout).
  std::map<int, std::int64_t> newest_stamp;
  std::set<int> mismatched_width_rigs;  // reported once each
  long long processed = 0, late = 0;
  // The idle clock starts with the first message: workers may take a while to start (loading,
  // first stereo), and fuse is a service that waits for them.
  std::optional<Clock::time_point> last_message;

  // Asking for more than the cap only makes LCM print a warning; the cap is reported here.
  const long long rmem_max = KernelReceiveBufferMax();
  const long long asked = rmem_max > 0 ? std::min(o.recv_buf_bytes, rmem_max) : o.recv_buf_bytes;
  const std::string receive_url = WithReceiveBuffer(o.lcm_url, asked);
  if (receive_url != o.lcm_url && asked < o.recv_buf_bytes) {
    pipe.ReportEvent("fuse: kernel UDP receive buffer capped at " + std::to_string(rmem_max) +
                     " bytes by net.core.rmem_max (asked " + std::to_string(o.recv_buf_bytes) +
                     "): bursts of rig clouds beyond it are lost unseen; raise net.core.rmem_max");
  }
  // Up to 64 of the largest messages accepted (512 MB at the default limit) wait for fusion.
  Inbox inbox(receive_url, o.max_message_bytes, std::max<std::size_t>(64 * o.max_message_bytes, 512u << 20));
  auto on_message = [&](const Received& m) {
    const std::string& channel = m.channel;
    const std::size_t size = m.size;
    last_message = Clock::now();
    if (channel == drivers::kGnssChannel) {
      if (m.overflow || size > o.max_message_bytes) {
        pipe.CountMalformed();
        pipe.ReportEvent("GNSS message on " + channel + " dropped (" + std::to_string(size) + " bytes, " +
                         (m.overflow ? "receive queue full" : "oversized") + ")");
        return;
      }
      try {
        const drivers::GnssFix fix = drivers::DecodeGnssMessage(m.data.data(), size, channel);
        fixes[fix.stamp_ns] = fix;
        if (fixes.size() > kFixesKept) fixes.erase(fixes.begin());
      } catch (const Error& e) {
        pipe.CountMalformed();
        pipe.ReportEvent(std::string("malformed message on ") + e.what());
      }
      return;
    }
    if (m.overflow) {
      const int rig = std::atoi(channel.c_str() + std::string(planning_iface::kRigCloudChannelPrefix).size());
      pipe.CountDropped(rig);
      pipe.ReportEvent("fuse behind: a " + std::to_string(size) + "-byte message on " + channel +
                       " dropped, the receive queue was full");
      return;
    }
    if (size > o.max_message_bytes) {
      pipe.CountMalformed();
      pipe.ReportEvent("oversized message on " + channel + ": " + std::to_string(size) +
                       " bytes > --max-message-bytes " + std::to_string(o.max_message_bytes) +
                       "; dropped undecoded");
      return;
    }
    std::string why;
    auto rc = planning_iface::DecodeRigCloud(m.data.data(), size, &why);
    if (!rc || channel != planning_iface::RigCloudChannel(rc->rig_id)) {
      pipe.CountMalformed();
      pipe.ReportEvent("malformed message on " + channel + ": " +
                       (why.empty() ? "rig id does not match the channel" : why));
      return;
    }
    bool known = false;
    for (const auto& r : calibration.rigs) known = known || r.rig_id == rc->rig_id;
    if (!known) {
      pipe.CountMalformed();
      pipe.ReportEvent("cloud of rig " + std::to_string(rc->rig_id) + " not in the calibration");
      return;
    }
    if (rc->stamp_ns <= last_done_stamp) {
      ++late;  // its frame was already processed without it
      pipe.CountDropped(rc->rig_id);
      pipe.ReportEvent("late cloud of rig " + std::to_string(rc->rig_id) + " for frame " +
                       std::to_string(rc->frame_sequence) + ": its frame was fused without it");
      return;
    }
    if (!pipe.made()) {
      pipe.Make(rc->image_width_px);
      std::fprintf(stderr, "romo fuse: defaults for %s (rig %d's first cloud)\n",
                   rc->image_width_px > 0 ? (std::to_string(rc->image_width_px) + "-px images").c_str()
                                          : "an image size the workers do not say",
                   rc->rig_id);
    } else if (rc->image_width_px > 0 && rc->image_width_px != pipe.image_width_px() &&
               mismatched_width_rigs.insert(rc->rig_id).second) {
      const std::string taken = pipe.image_width_px() > 0
                                    ? "its defaults for " + std::to_string(pipe.image_width_px()) + " px"
                                    : "its fallback defaults (the first cloud did not say its image width)";
      pipe.ReportEvent("rig " + std::to_string(rc->rig_id) + " sends clouds of " + std::to_string(rc->image_width_px) +
                       "-px images; fuse took " + taken);
    }
    std::int64_t& newest = newest_stamp[rc->rig_id];
    newest = std::max(newest, rc->stamp_ns);
    Pending& p = pending[rc->stamp_ns];
    if (p.rigs.empty()) p.first_arrival = Clock::now();
    p.sequence = rc->frame_sequence;
    if (rc->vehicle) p.vehicle = rc->vehicle;
    pipeline::RigInput in;
    in.rig_id = rc->rig_id;
    in.stamp_ns = rc->capture_stamp_ns;  // motion-compensated to the frame's stamp
    in.cloud = std::move(rc->cloud);
    in.stereo_ms = rc->stereo_ms;
    p.rigs[in.rig_id] = std::move(in);
  };

  auto process = [&](std::map<std::int64_t, Pending>::iterator it) {
    std::vector<pipeline::RigInput> rigs;
    for (auto& [id, in] : it->second.rigs) rigs.push_back(std::move(in));
    // The newest fix not after the frame, unless it is too old to place the vehicle.
    std::optional<drivers::GnssFix> gnss;
    auto fix = fixes.upper_bound(it->first);
    if (fix != fixes.begin() &&
        it->first - std::prev(fix)->first <= static_cast<std::int64_t>(o.gnss_max_age_ms) * 1000000) {
      gnss = std::prev(fix)->second;
      ++frames_with_fix;
    }
    const auto result = pipe.Get().ProcessClouds(it->first, it->second.sequence, rigs, it->second.vehicle, gnss);
    sink.Write(nullptr, result, {});
    last_done_stamp = it->first;
    ++processed;
    pending.erase(pending.begin(), std::next(it));
  };

  const std::size_t all = calibration.rigs.size();
  // Subscribed from here on: a sender (or test) may start once this line is out.
  std::fprintf(stderr, "romo fuse: listening on %s for %zu rigs\n", o.lcm_url.c_str(), all);
  std::fflush(stderr);
  while (o.frames <= 0 || processed < o.frames) {
    for (const Received& m : inbox.Take(20)) on_message(m);
    // Oldest first: complete frames at once, incomplete ones after the timeout or when a newer
    // frame is already complete (its rigs will not come back for the old stamp).
    while (!pending.empty()) {
      auto it = pending.begin();
      const bool complete = it->second.rigs.size() >= all;
      // Every absent rig has already moved on to a newer frame: nothing more will come.
      bool skipped = true;
      for (const auto& rig : calibration.rigs) {
        if (it->second.rigs.count(rig.rig_id)) continue;
        const auto n = newest_stamp.find(rig.rig_id);
        skipped = skipped && n != newest_stamp.end() && n->second > it->first;
      }
      const bool timed_out = Clock::now() - it->second.first_arrival > std::chrono::milliseconds(o.timeout_ms);
      bool newer_complete = false;
      for (auto jt = std::next(it); jt != pending.end(); ++jt) newer_complete |= jt->second.rigs.size() >= all;
      if (!(complete || skipped || timed_out || newer_complete)) break;
      process(it);
    }
    if (last_message && Clock::now() - *last_message > std::chrono::duration<double>(o.idle_exit_s)) break;
  }
  while (!pending.empty() && (o.frames <= 0 || processed < o.frames)) process(pending.begin());
  // Faults found after the last frame (bad or late messages) still reach the status and summary.
  if (auto status = pipe.Get().TakePendingStatus()) sink.WriteStatus(*status);
  sink.Finish("\"late_clouds\": " + std::to_string(late) + ", \"frames_with_gnss\": " + std::to_string(frames_with_fix) +
              ", \"geodetic\": " + (frames_with_fix > 0 ? "true" : "false") +
              ", \"image_width_px\": " + std::to_string(pipe.image_width_px()));
  std::fprintf(stderr, "romo fuse: %lld frames processed, %lld late clouds\n", processed, late);
}

}  // namespace

ROMO_REGISTER_COMMAND([](CLI::App& root) {
  auto opts = std::make_shared<FuseOptions>();
  CLI::App* cmd = root.add_subcommand("fuse", "Mapping, objects and planning on the clouds of romo stereo-workers");
  cmd->add_option("--lcm-url", opts->lcm_url, "LCM URL the workers publish on")->required();
  cmd->add_option("--calib", opts->calib, "calibration (default: the sample RoMo calibration)");
  cmd->add_option("--out", opts->out_dir, "also write outputs like romo replay");
  cmd->add_option("--timeout-ms", opts->timeout_ms, "wait this long for a frame's missing rigs")->capture_default_str();
  cmd->add_option("--idle-exit", opts->idle_exit_s, "exit after this many seconds without messages (counted from the first)")->capture_default_str();
  cmd->add_option("--frames", opts->frames, "exit after this many frames (0 = until idle)");
  AddPictureOptions(*cmd, opts->pictures);
  cmd->add_option("--max-message-bytes", opts->max_message_bytes,
                  "refuse (count as malformed) rig clouds larger than this")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--recv-buf-bytes", opts->recv_buf_bytes,
                  "kernel UDP receive buffer to ask for on udpm:// (0 = the system default)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--gnss-max-age-ms", opts->gnss_max_age_ms,
                  "a frame uses the newest ROMO_GNSS fix at most this much older than it (else: GNSS gap)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->callback([opts] { Fuse(*opts); });
});

}  // namespace romo::tools
