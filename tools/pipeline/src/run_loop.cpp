#include "romo/pipeline/run_loop.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

namespace romo::pipeline {

LoopedLog::LoopedLog(drivers::LogReader& reader) : reader_(reader) {}

std::optional<drivers::FrameSet> LoopedLog::Next() {
  std::optional<drivers::FrameSet> frames = reader_.Next();
  if (!frames) {
    if (!first_stamp_ns_) return std::nullopt;  // an empty recording stays empty
    reader_.Seek(0.0);
    frames = reader_.Next();
    if (!frames) return std::nullopt;
    ++loops_;
    // The next pass starts one period after the last frame of this one.
    stamp_offset_ns_ += *last_stamp_ns_ - *first_stamp_ns_ + period_ns_.value_or(100000000);
    sequence_offset_ += last_sequence_ - first_sequence_ + 1;
  }
  if (!first_stamp_ns_) {
    first_stamp_ns_ = frames->stamp_ns;
    first_sequence_ = frames->sequence;
  } else if (loops_ == 0 && frames->stamp_ns > *last_stamp_ns_) {
    period_ns_ = frames->stamp_ns - *last_stamp_ns_;
  }
  if (loops_ == 0) {
    last_stamp_ns_ = frames->stamp_ns;
    last_sequence_ = frames->sequence;
  }
  if (loops_ > 0) {
    const std::int64_t dt = stamp_offset_ns_;
    frames->stamp_ns += dt;
    frames->sequence += sequence_offset_;
    for (auto& stereo : frames->stereo) {
      stereo.left.stamp_ns += dt;
      stereo.right.stamp_ns += dt;
    }
    if (frames->rgbd) frames->rgbd->stamp_ns += dt;
    if (frames->vehicle) frames->vehicle->stamp_ns += dt;
    if (frames->gnss) frames->gnss->stamp_ns += dt;
  }
  return frames;
}

const drivers::Calibration* LoopedLog::calibration() const { return reader_.calibration(); }
drivers::SourceStatus LoopedLog::status() const { return reader_.status(); }

RunStats RunFrames(drivers::FrameSource& source, Pipeline& pipeline, OutputSink& outputs,
                   const RunOptions& options, const PassthroughFn& passthrough,
                   const ProgressFn& progress) {
  using Clock = std::chrono::steady_clock;
  RunStats stats;
  const auto start = Clock::now();
  std::optional<std::int64_t> first_stamp, last_stamp;
  // The source's own events (damaged or dropped messages, a truncated recording) go into the
  // perception status with the frame they came before, or into a last status at the end.
  std::size_t source_events_reported = 0;
  const auto report_source_events = [&] {
    const std::vector<std::string> events = source.status().events;
    for (std::size_t i = source_events_reported; i < events.size(); ++i) pipeline.ReportEvent("source: " + events[i]);
    source_events_reported = std::max(source_events_reported, events.size());
  };
  while (options.max_frames <= 0 || stats.frames < options.max_frames) {
    if (options.duration_s > 0.0 &&
        std::chrono::duration<double>(Clock::now() - start).count() >= options.duration_s) {
      break;
    }
    std::optional<drivers::FrameSet> frames = source.Next();
    if (!frames) break;
    std::vector<drivers::LogEvent> extra = passthrough ? passthrough() : std::vector<drivers::LogEvent>{};
    if (last_stamp && frames->stamp_ns <= *last_stamp) {
      // Out-of-order input: skipped, counted and reported, never processed backwards.
      ++stats.skipped_out_of_order;
      for (const auto& st : frames->stereo) pipeline.CountDropped(st.rig_id);
      pipeline.ReportEvent("frame " + std::to_string(frames->sequence) + " skipped: stamp " +
                           std::to_string(frames->stamp_ns) + " ns not after " +
                           std::to_string(*last_stamp) + " ns");
      continue;
    }
    if (!first_stamp) first_stamp = frames->stamp_ns;
    last_stamp = frames->stamp_ns;
    if (options.realtime) {
      const auto due = start + std::chrono::nanoseconds(frames->stamp_ns - *first_stamp);
      std::this_thread::sleep_until(due);
    }
    report_source_events();
    const FrameResult result = pipeline.Process(*frames);
    outputs.Write(&*frames, result, extra);
    ++stats.frames;
    if (progress) progress(stats.frames, result);
  }
  report_source_events();
  if (auto status = pipeline.TakePendingStatus()) outputs.WriteStatus(*status);
  stats.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return stats;
}

}  // namespace romo::pipeline
