#include "romo/pipeline/run_loop.hpp"

#include <chrono>
#include <thread>

namespace romo::pipeline {

RunStats RunFrames(drivers::FrameSource& source, Pipeline& pipeline, OutputSink& outputs,
                   const RunOptions& options, const PassthroughFn& passthrough,
                   const ProgressFn& progress) {
  using Clock = std::chrono::steady_clock;
  RunStats stats;
  const auto start = Clock::now();
  std::optional<std::int64_t> first_stamp, last_stamp;
  while (options.max_frames <= 0 || stats.frames < options.max_frames) {
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
    for (const auto& e : source.status().events) (void)e;
    const FrameResult result = pipeline.Process(*frames);
    outputs.Write(&*frames, result, extra);
    ++stats.frames;
    if (progress) progress(stats.frames, result);
  }
  stats.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return stats;
}

}  // namespace romo::pipeline
