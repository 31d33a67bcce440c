#pragma once
/// Scores a run's outputs log against the simulator's ground truth channels (`romo eval scene`,
/// and the report of `romo run`): detection precision/recall for cars and pedestrians within a
/// range of the ego, box centre error, ID switches, prediction ADE/FDE and the parking slot.
#include <cstdint>
#include <string>
#include <vector>

namespace romo::pipeline {

struct SceneEvalParams {
  double range_m = 15.0;              ///< objects farther from the ego centre are not scored
  double car_match_m = 1.5;           ///< detection-to-truth centre distance for a match
  double pedestrian_match_m = 0.8;
  double slot_match_m = 1.0;          ///< reported slot centre to bay centre for a match
  double bay_visible_range_m = 10.0;  ///< a bay this close to the ego counts as fully visible
  /// For the "visible" scores: a truth counts when at least this fraction of its surface turned
  /// to the cameras is in some rig's view and not hidden behind another object (sim::VisibleFraction);
  /// a detection of a hidden one is neither right nor wrong there.
  double min_visible_fraction = 0.25;
};

struct ClassScore {
  std::int64_t truths = 0, detections = 0, matched_truths = 0, matched_detections = 0;
  double center_err_m_median = 0.0;  ///< of the matched boxes (car and pedestrian only)
  double precision() const { return detections ? double(matched_detections) / detections : 1.0; }
  double recall() const { return truths ? double(matched_truths) / truths : 1.0; }
};

/// Truths hidden from the cameras now (below SceneEvalParams::min_visible_fraction): only memory
/// (remembered parked cars, coasting tracks) can report them. seen_before counts those the cameras
/// saw, within the range scored, in an earlier frame of the same run (what memory could carry), and
/// how many of them were found.
struct HiddenScore {
  std::int64_t truths = 0, matched_truths = 0, seen_before = 0, seen_before_matched = 0;
};

/// A visible truth no detection of its class matched: what was reported nearest to it instead.
struct SceneMiss {
  int log = 0;             ///< index among the logs scored together
  std::int64_t frame = 0;  ///< index among the log's scored frames
  std::string class_name;
  int truth_id = -1;
  double x_m = 0.0, y_m = 0.0;  ///< truth centre, vehicle frame
  double visible_fraction = 0.0;
  std::string nearest_class;  ///< nearest detection of any class ("" when none within 3 m)
  double nearest_m = 0.0;
  double nearest_length_m = 0.0, nearest_width_m = 0.0, nearest_height_m = 0.0;
  double nearest_yaw_err_deg = 0.0;  ///< between the box axes, 0..90
  double nearest_along_m = 0.0, nearest_across_m = 0.0;  ///< its centre's offset along / across the truth's length
  int nearest_points = 0;
};

/// A car or pedestrian detection no truth of its class matched (among visible truths' frames).
struct SceneFalseAlarm {
  int log = 0;
  std::int64_t frame = 0;
  std::string class_name;
  double x_m = 0.0, y_m = 0.0, length_m = 0.0, width_m = 0.0, height_m = 0.0;  ///< vehicle frame
  int points = 0;
  int nearest_truth_id = -1;  ///< of any class
  std::string nearest_truth_class;
  double nearest_truth_m = 0.0;
  /// The truth whose footprint holds the detection's centre (a fragment of it), -1 if none.
  int inside_truth_id = -1;
  std::string inside_truth_class;
};

/// A bay in one frame of one run.
struct SceneBayAt {
  int log = 0;
  std::int64_t frame = 0;
  int bay_id = -1;
  double x_m = 0.0, y_m = 0.0;  ///< bay centre, vehicle frame
};

/// A feasible bay fully visible in a frame where no feasible slot was reported at it: what was
/// reported nearest to it instead.
struct SceneSlotMiss : SceneBayAt {
  bool slot_near = false;       ///< a slot was reported within SceneEvalParams::slot_match_m
  double slot_m = 0.0;          ///< its target's distance from the bay centre
  std::string slot_reason;      ///< why it was reported infeasible
};

/// A frame where a bay too narrow for the ego was reported feasible: the slot reported there.
struct SceneNarrowFeasible : SceneBayAt {
  double bay_width_m = 0.0;     ///< the bay's true width along the row
  double slot_length_m = 0.0;   ///< the free length the slot was reported with
  int prev_id = -1, next_id = -1;  ///< the neighbours' track ids it was bounded by
  double confidence = 0.0;
};

struct SceneEval {
  std::int64_t frames = 0;
  std::int64_t logs = 0;  ///< runs pooled (counts summed, medians over all matches)
  double range_m = 15.0;  ///< SceneEvalParams::range_m scored within
  double slot_match_m = 1.0;  ///< SceneEvalParams::slot_match_m
  ClassScore car, pedestrian;  ///< every truth within range
  /// Only truths the cameras can see (needs the calibration in the log: visibility_scored).
  ClassScore car_visible, pedestrian_visible;
  HiddenScore car_hidden, pedestrian_hidden;  ///< (only when visibility_scored)
  bool visibility_scored = false;
  double box_center_err_m_median = 0.0;
  double box_size_err_m_median = 0.0;   ///< |truth size - box size| (length, width, height)
  double car_yaw_err_deg_median = 0.0;  ///< between the box axes, 0..90 (cars only)
  std::int64_t id_switches = 0;
  double ade_m = 0.0, fde_m = 0.0;
  std::int64_t predictions_scored = 0;
  std::int64_t slot_visible_frames = 0, slot_found_frames = 0;
  double slot_center_err_m = 0.0;  ///< median over found frames
  double slot_yaw_err_deg = 0.0;   ///< median over found frames
  std::vector<SceneMiss> misses;  ///< visible truths missed (only when visibility_scored)
  /// Truths hidden now that the cameras saw earlier in the run, missed (what memory and coasting
  /// tracks failed to carry; only when visibility_scored).
  std::vector<SceneMiss> hidden_misses;
  std::vector<SceneFalseAlarm> false_alarms;  ///< unmatched detections (only when visibility_scored)
  std::vector<SceneSlotMiss> slot_misses;  ///< visible feasible bays not found
  std::vector<SceneNarrowFeasible> narrow_feasible;  ///< each frame the narrow bay was reported feasible
  std::int64_t narrow_reported_feasible() const { return static_cast<std::int64_t>(narrow_feasible.size()); }
  /// {"frames":N, "car":{...}, ...} exactly as the issue specifies.
  std::string ToJson() const;
  std::string ToText() const;
  /// One line per miss (frame, class, where, visibility, the nearest detection), then one per
  /// hidden truth seen before and missed now (the same, marked "hidden now"), then one per
  /// false alarm (where, size, the nearest truth), then one per visible feasible bay not found
  /// (where, the nearest slot reported and why it was infeasible), then one per narrow bay
  /// reported feasible (where, the slot's length and the neighbours that bounded it).
  std::string MissesText() const;
};

/// @throws romo::Error when the log cannot be read or holds no ground truth frames.
SceneEval EvaluateSceneLog(const std::string& log_path, const SceneEvalParams& params = {});
/// Several runs (seeds) scored as one: counts summed, medians over every match, ID switches per
/// run; the visibility-aware scores only when every log carries its calibration.
/// @throws romo::Error naming the first log that cannot be read or holds no ground truth frames.
SceneEval EvaluateSceneLogs(const std::vector<std::string>& log_paths, const SceneEvalParams& params = {});

}  // namespace romo::pipeline
