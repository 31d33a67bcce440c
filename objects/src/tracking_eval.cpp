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
  Eigen::MatrixXd cost(static_cast<Eigen::Index>(ground_truth.size()),
                       static_cast<Eigen::Index>(tracks.size()));
  for (std::size_t g = 0; g < ground_truth.size(); ++g) {
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      const double d = (ground_truth[g].xy_m - tracks[t].xy_m).norm();
      cost(static_cast<Eigen::Index>(g), static_cast<Eigen::Index>(t)) =
          d <= max_match_distance_m_ ? d : kForbiddenCost;
    }
  }
  const Assignment a = SolveAssignment(cost);
  std::int64_t matched_tracks = 0;
  for (std::size_t g = 0; g < ground_truth.size(); ++g) {
    const int t = a.row_to_col[g];
    if (t < 0) {
      ++score_.misses;
      continue;
    }
    ++score_.matches;
    ++matched_tracks;
    const double e = cost(static_cast<Eigen::Index>(g), t);
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
