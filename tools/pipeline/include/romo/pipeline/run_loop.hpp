#pragma once
/// The frame loop shared by `romo run` and `romo replay`: source -> pipeline -> outputs, with
/// bad input degraded and reported (out-of-order stamps skipped and counted, failed rigs
/// dropped), optional real-time pacing and a progress callback.
#include <cstdint>
#include <functional>
#include <vector>

#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/pipeline/outputs.hpp"
#include "romo/pipeline/pipeline.hpp"

namespace romo::pipeline {

struct RunOptions {
  bool realtime = false;      ///< pace frames by their stamps instead of as fast as possible
  std::int64_t max_frames = 0;  ///< 0 = until the source ends
};

struct RunStats {
  std::int64_t frames = 0;
  std::int64_t skipped_out_of_order = 0;
  double wall_s = 0.0;
};

/// Raw events to copy into the outputs log with the frame just read (e.g. ground truth).
using PassthroughFn = std::function<std::vector<drivers::LogEvent>()>;
/// Called after each frame with the frames done so far and the frame's result.
using ProgressFn = std::function<void(std::int64_t done, const FrameResult& result)>;

RunStats RunFrames(drivers::FrameSource& source, Pipeline& pipeline, OutputSink& outputs,
                   const RunOptions& options, const PassthroughFn& passthrough,
                   const ProgressFn& progress);

}  // namespace romo::pipeline
