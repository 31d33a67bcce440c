#include "romo/objects/tracking_eval.hpp"

#include <algorithm>

#include "romo/core/check.hpp"
#include "romo/objects/hungarian.hpp"

namespace romo::objects {

IdSwitchCounter::IdSwitchCounter(double max_match_distance_m)
    : max_match_distance_m_(max_match_distance_m) {
  ROMO_THROW_UNLESS(max_match_distance_m > 0.0);
}

void IdSwitchCounter::AddFrame(const std::vector<IdPosition>& ground_truth,
                               const std::vector<IdPosition>& tracks) {
  ++score_.frames;
  score_.ground_truth_instances += static_cast<std::int64_t>(ground_truth.size());
  auto last_track_of = [&](int object) -> int {
    auto it = std::lower_bound(last_match_.begin(), last_match_.end(), std::make_pair(object, 0),
                               [](const auto& x, const auto& y) { return x.first < y.first; });
    return it != last_match_.end() && it->first == object ? it->second : -1;
  };
  // CLEAR-MOT: a correspondence from the previous frame is kept while it is still within the
  // match distance (two close objects must not trade tracks just because the minimum-distance
  // matching flips); the rest is matched optimally.
  std::vector<int> match(ground_truth.size(), -1);  // track index per object
  std::vector<char> track_taken(tracks.size(), 0);
  for (std::size_t g = 0; g < ground_truth.size(); ++g) {
    const int previous = last_track_of(ground_truth[g].id);
    if (previous < 0) continue;
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      if (tracks[t].id == previous && !track_taken[t] &&
          (ground_truth[g].xy_m - tracks[t].xy_m).norm() <= max_match_distance_m_) {
        match[g] = static_cast<int>(t);
        track_taken[t] = 1;
        break;
      }
    }
  }
  std::vector<int> free_objects, free_tracks;
  for (std::size_t g = 0; g < ground_truth.size(); ++g) {
    if (match[g] < 0) free_objects.push_back(static_cast<int>(g));
  }
  for (std::size_t t = 0; t < tracks.size(); ++t) {
    if (!track_taken[t]) free_tracks.push_back(static_cast<int>(t));
  }
  std::vector<Eigen::Vector2d> free_object_xy, free_track_xy;
  for (const int g : free_objects) free_object_xy.push_back(ground_truth[static_cast<std::size_t>(g)].xy_m);
  for (const int t : free_tracks) free_track_xy.push_back(tracks[static_cast<std::size_t>(t)].xy_m);
  for (const auto& [g, t] : MatchWithinGate(free_object_xy, free_track_xy, max_match_distance_m_)) {
    match[static_cast<std::size_t>(free_objects[static_cast<std::size_t>(g)])] =
        free_tracks[static_cast<std::size_t>(t)];
  }
  std::int64_t matched_tracks = 0;
  for (std::size_t g = 0; g < ground_truth.size(); ++g) {
    const int t = match[g];
    if (t < 0) {
      ++score_.misses;
      continue;
    }
    ++score_.matches;
    ++matched_tracks;
    const double e = (ground_truth[g].xy_m - tracks[static_cast<std::size_t>(t)].xy_m).norm();
    error_sum_m_ += e;
    score_.max_error_m = std::max(score_.max_error_m, e);
    const int object = ground_truth[g].id;
    const int track = tracks[static_cast<std::size_t>(t)].id;
    auto it = std::lower_bound(last_match_.begin(), last_match_.end(), std::make_pair(object, 0),
                               [](const auto& x, const auto& y) { return x.first < y.first; });
    if (it != last_match_.end() && it->first == object) {
      if (it->second != track) ++score_.id_switches;
      it->second = track;
    } else {
      last_match_.insert(it, {object, track});
    }
  }
  score_.false_tracks += static_cast<std::int64_t>(tracks.size()) - matched_tracks;
}

TrackingScore IdSwitchCounter::score() const {
  TrackingScore s = score_;
  s.mean_error_m = s.matches > 0 ? error_sum_m_ / static_cast<double>(s.matches) : 0.0;
  return s;
}

}  // namespace romo::objects
