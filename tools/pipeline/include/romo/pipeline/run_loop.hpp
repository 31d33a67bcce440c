#pragma once
/// The frame loop shared by `romo run` and `romo replay`: source -> pipeline -> outputs, with
/// bad input degraded and reported (out-of-order stamps skipped and counted, failed rigs
/// dropped), optional real-time pacing and a progress callback.
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "romo/drivers/frame_source.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/pipeline/outputs.hpp"
#include "romo/pipeline/pipeline.hpp"

namespace romo::pipeline {

struct RunOptions {
  bool realtime = false;      ///< pace frames by their stamps instead of as fast as possible
  std::int64_t max_frames = 0;  ///< 0 = until the source ends
  double duration_s = 0.0;    ///< > 0: stop after the frame that ends past this much wall time
};

struct RunStats {
  std::int64_t frames = 0;
  std::int64_t skipped_out_of_order = 0;
  double wall_s = 0.0;
};

/// A recording played over and over (soak runs, `romo replay --loop`): at the end it seeks back
/// to the start and shifts every stamp and sequence by the recording's span plus one frame
/// period, so the pipeline sees one continuous drive whose time only moves forward.
class LoopedLog : public drivers::FrameSource {
 public:
  /// @param reader a recording opened without its own loop option; must outlive this.
  explicit LoopedLog(drivers::LogReader& reader);
  std::optional<drivers::FrameSet> Next() override;
  const drivers::Calibration* calibration() const override;
  drivers::SourceStatus status() const override;
  /// Times the recording started over.
  std::int64_t loops() const { return loops_; }

 private:
  drivers::LogReader& reader_;
  std::int64_t loops_ = 0;
  std::int64_t stamp_offset_ns_ = 0;
  std::uint64_t sequence_offset_ = 0;
  std::optional<std::int64_t> first_stamp_ns_, last_stamp_ns_, period_ns_;
  std::uint64_t first_sequence_ = 0, last_sequence_ = 0;
};

/// Raw events to copy into the outputs log with the frame just read (e.g. ground truth).
using PassthroughFn = std::function<std::vector<drivers::LogEvent>()>;
/// Called after each frame with the frames done so far and the frame's result.
using ProgressFn = std::function<void(std::int64_t done, const FrameResult& result)>;

RunStats RunFrames(drivers::FrameSource& source, Pipeline& pipeline, OutputSink& outputs,
                   const RunOptions& options, const PassthroughFn& passthrough,
                   const ProgressFn& progress);

}  // namespace romo::pipeline
