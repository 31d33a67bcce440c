#pragma once
/// Scoring tracks against ground truth: ID switches (CLEAR-MOT style), misses and position error.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace romo::objects {

/// An id with a ground-plane position (a ground-truth object or a track).
struct IdPosition {
  int id = 0;
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();
};

struct TrackingScore {
  std::int64_t frames = 0;
  std::int64_t ground_truth_instances = 0;  ///< object-frames
  std::int64_t matches = 0;
  std::int64_t misses = 0;          ///< object-frames with no track within the match distance
  std::int64_t false_tracks = 0;    ///< track-frames matched to no object
  std::int64_t id_switches = 0;     ///< an object's matched track id changed
  double mean_error_m = 0.0;        ///< over matches
  double max_error_m = 0.0;
};

/// Counts ID switches frame by frame (CLEAR-MOT): an object keeps last frame's track while it is
/// within max_match_distance_m; the other objects and tracks are matched one-to-one by minimum
/// total distance (Hungarian) within it. An object whose matched track id differs from the id it
/// was last matched to counts one switch.
class IdSwitchCounter {
 public:
  explicit IdSwitchCounter(double max_match_distance_m = 1.0);
  void AddFrame(const std::vector<IdPosition>& ground_truth, const std::vector<IdPosition>& tracks);
  TrackingScore score() const;

 private:
  double max_match_distance_m_;
  TrackingScore score_;
  double error_sum_m_ = 0.0;
  std::vector<std::pair<int, int>> last_match_;  ///< (object id, track id), sorted by object
};

}  // namespace romo::objects
