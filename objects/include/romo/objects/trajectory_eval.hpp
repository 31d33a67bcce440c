#pragma once
/// Scoring path predictors on recorded pedestrian trajectories in the ETH/UCY text format
/// (`frame ped_id x y` per line, tab or space separated, metres; frame step 10 = 0.4 s).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "romo/objects/path_prediction.hpp"

namespace romo::objects {

struct TrajectorySample {
  double frame = 0.0;
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();
};

/// A parsed trajectory file: samples per pedestrian sorted by frame, and what was skipped.
struct TrajectorySet {
  std::string path;
  std::map<long, std::vector<TrajectorySample>> tracks;  ///< by pedestrian id
  std::int64_t rows_used = 0;
  std::int64_t skipped_malformed = 0;   ///< not 4 numbers, or a non-integer pedestrian id
  std::int64_t skipped_nonfinite = 0;   ///< NaN or infinite frame/x/y
  std::int64_t skipped_duplicate = 0;   ///< a second row for the same (frame, pedestrian)
  std::int64_t pedestrians_seen_once = 0;  ///< kept, but they can fill no window
  /// The first few problems, each "file:line: what (value)".
  std::vector<std::string> notes;
  std::int64_t skipped_total() const {
    return skipped_malformed + skipped_nonfinite + skipped_duplicate;
  }
};

/// Reads an ETH/UCY trajectory file. Bad rows are skipped and counted (see TrajectorySet), or
/// with @p strict the first one throws.
/// @throws romo::Error when the file cannot be read, has no valid row, or (strict) any bad row;
///   the message names the file, line and value.
TrajectorySet ReadEthUcy(const std::string& path, bool strict = false);

struct WindowParams {
  int obs = 8;    ///< observed steps
  int pred = 12;  ///< predicted steps
  /// Frame-number difference of one step; 0 = infer (most common step within pedestrians).
  double frame_step = 0.0;
  double step_s = 0.4;  ///< seconds per step (ETH/UCY: 2.5 Hz)
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

struct DisplacementError {
  double ade_m = 0.0;  ///< mean over windows of the mean error over the predicted steps
  double fde_m = 0.0;  ///< mean over windows of the error at the last predicted step
};

struct TrajectoryEvalResult {
  std::int64_t windows = 0;
  double frame_step = 0.0;  ///< the frame step used
  DisplacementError romo;   ///< the RLS predictor
  DisplacementError cv;     ///< the constant-velocity baseline
};

/// The frame step of @p set: the most common frame difference of consecutive samples of a
/// pedestrian. @throws romo::Error when no pedestrian has two samples.
double InferFrameStep(const TrajectorySet& set);

/// Runs the RLS predictor (@p rls, kind forced to RLS) and the CV baseline on every window of
/// obs + pred consecutive steps (sliding by one) of every pedestrian.
/// @throws romo::Error when the file yields no window.
TrajectoryEvalResult EvaluateTrajectories(const TrajectorySet& set, const WindowParams& window,
                                          const PredictorParams& rls);

}  // namespace romo::objects
