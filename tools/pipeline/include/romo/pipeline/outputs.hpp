#pragma once
/// Where a pipeline run's results go: LCM (publish at the end of each frame), an LCM log of
/// inputs + outputs, the pedestrian prediction CSV, a top-view PNG per frame, a summary PNG per
/// maneuver stage and a JSON summary. Shared by `romo run`, `romo replay` and `romo fuse`.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "romo/core/json.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/pipeline/pipeline.hpp"

namespace romo::pipeline {

struct OutputOptions {
  std::string out_dir;         ///< "" writes no files
  std::string lcm_url;         ///< "" publishes nothing
  bool log_inputs = true;      ///< inputs (images, vehicle state, GNSS) into outputs.lcmlog
  bool frame_pictures = true;  ///< frames/frame_<seq>.png
  int picture_size_px = 800;
  double picture_span_m = 36.0;  ///< metres across a picture, centred on the vehicle
};

/// Output channels written per frame (besides the inputs and passed-through channels).
std::vector<std::string> OutputChannels();

class OutputSink {
 public:
  /// Creates out_dir (and frames/), opens the log and CSV, connects to LCM.
  /// @throws romo::Error when the folder or files cannot be created or LCM cannot open.
  OutputSink(const drivers::Calibration& calibration, const OutputOptions& options);
  ~OutputSink();
  OutputSink(const OutputSink&) = delete;
  OutputSink& operator=(const OutputSink&) = delete;

  /// Publishes and writes one frame. @p inputs may be null (e.g. `romo fuse`); @p passthrough
  /// are raw events to copy into the log (ground truth of a simulated or recorded run).
  void Write(const drivers::FrameSet* inputs, const FrameResult& result,
             const std::vector<drivers::LogEvent>& passthrough);

  /// Publishes and logs a status without a frame (faults found after the last frame); its events
  /// also go into summary.json.
  void WriteStatus(const planning_iface::PerceptionStatus& status);

  /// Writes the stage summaries and summary.json, closes files. Idempotent.
  /// @param extra JSON members (without braces) added to summary.json, e.g. "\"source\":\"x\"".
  void Finish(const std::string& extra_json = "");

  std::int64_t frames_written() const;
  /// Path of the outputs log ("" without out_dir).
  std::string log_path() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

using ::romo::JsonEscape;

}  // namespace romo::pipeline
