#include "romo/pipeline/scene_eval.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "romo/core/angles.hpp"
#include "romo/core/check.hpp"
#include "romo/core/statistics.hpp"
#include "romo/drivers/recording.hpp"
#include "romo/objects/hungarian.hpp"
#include "romo/objects/prediction_log.hpp"
#include "romo/objects/tracking_eval.hpp"
#include "romo/planning_iface/messages.hpp"
#include "romo/sim/ground_truth.hpp"
#include "romo/sim/visibility.hpp"

namespace romo::pipeline {
namespace pi = planning_iface;
namespace {

struct Frame {
  std::optional<sim::GroundTruth> truth;
  std::optional<pi::ObstacleList> obstacles;
  std::optional<pi::ParkingSlotReport> slots;
  std::vector<objects::PedestrianPrediction> predictions;
};

// Keeps the entries of @p v whose @p new_index is >= 0 (ascending), at that index.
template <class T>
void Compact(std::vector<T>* v, const std::vector<int>& new_index) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < v->size(); ++i) {
    if (new_index[i] >= 0) (*v)[kept++] = (*v)[i];
  }
  v->resize(kept);
}

// A world-frame heading as seen in the frame @p T_to maps into.
double HeadingIn(const Eigen::Isometry3d& T_to, double yaw_rad) {
  const Eigen::Vector3d heading = T_to.linear() * Eigen::Vector3d(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  return std::atan2(heading.y(), heading.x());
}

SceneMiss DescribeMiss(int log, std::int64_t frame, const std::string& cls, int id, const Eigen::Vector2d& at,
                       double yaw_rad, double visible_fraction, const std::vector<pi::Obstacle>& obstacles) {
  constexpr double kNearestWithinM = 3.0;
  SceneMiss miss;
  miss.log = log;
  miss.frame = frame;
  miss.class_name = cls;
  miss.truth_id = id;
  miss.x_m = at.x();
  miss.y_m = at.y();
  miss.visible_fraction = visible_fraction;
  double best = kNearestWithinM;
  for (const auto& o : obstacles) {
    const double d = (o.center_m.head<2>() - at).norm();
    if (d >= best) continue;
    best = d;
    miss.nearest_class = o.class_name;
    miss.nearest_m = d;
    miss.nearest_length_m = o.size_m.x();
    miss.nearest_width_m = o.size_m.y();
    miss.nearest_height_m = o.size_m.z();
    miss.nearest_points = o.num_points;
    miss.nearest_yaw_err_deg = AxisAngleDeg(yaw_rad, o.yaw_rad);
    const Eigen::Vector2d offset = o.center_m.head<2>() - at;
    miss.nearest_along_m = offset.dot(Eigen::Vector2d(std::cos(yaw_rad), std::sin(yaw_rad)));
    miss.nearest_across_m = offset.dot(Eigen::Vector2d(-std::sin(yaw_rad), std::cos(yaw_rad)));
  }
  return miss;
}

SceneFalseAlarm DescribeFalseAlarm(int log, std::int64_t frame, const std::string& cls, const pi::Obstacle& d,
                                   const std::vector<sim::GtBox>& truths, const Eigen::Isometry3d& T_vw) {
  SceneFalseAlarm alarm;
  alarm.log = log;
  alarm.frame = frame;
  alarm.class_name = cls;
  alarm.x_m = d.center_m.x();
  alarm.y_m = d.center_m.y();
  alarm.length_m = d.size_m.x();
  alarm.width_m = d.size_m.y();
  alarm.height_m = d.size_m.z();
  alarm.points = d.num_points;
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d world = T_vw.inverse() * d.center_m;
  for (const auto& o : truths) {
    // The footprint alone: the detection's centre taken at the truth's mid-height.
    if (o.Contains(Eigen::Vector3d(world.x(), world.y(), o.center_m.z()))) {
      alarm.inside_truth_id = o.id;
      alarm.inside_truth_class = o.class_name;
    }
    const double dist = ((T_vw * o.center_m).head<2>() - d.center_m.head<2>()).norm();
    if (dist >= best) continue;
    best = dist;
    alarm.nearest_truth_id = o.id;
    alarm.nearest_truth_class = o.class_name;
    alarm.nearest_truth_m = dist;
  }
  return alarm;
}

// Scores logs one after the other into pooled counts and error lists.
class Scorer {
 public:
  explicit Scorer(const SceneEvalParams& params) : params_(params) {}
  void Add(const std::string& log_path, int log_index);
  SceneEval Finish();

 private:
  const SceneEvalParams& params_;
  SceneEval out_;
  int calibrated_logs_ = 0;
  std::vector<double> center_errors_, size_errors_, car_yaw_errors_, slot_center_, slot_yaw_;
  std::vector<double> car_center_errors_, pedestrian_center_errors_, ade_list_, fde_list_;
};

void Scorer::Add(const std::string& log_path, int log_index) {
  std::int64_t truncated = -1;
  const auto events = drivers::ReadAllEvents(log_path, &truncated);
  std::map<std::int64_t, Frame> frames;  // by stamp_ns
  std::optional<drivers::Calibration> calibration;
  for (const auto& e : events) {
    if (e.channel == drivers::kCalibrationChannel && !calibration) {
      try {
        calibration = drivers::CalibrationFromEvent(e, log_path);
      } catch (const Error&) {
        // Without a readable calibration the visibility-aware scores are left out (said in the text).
      }
    } else if (e.channel == sim::kGroundTruthChannel) {
      auto gt = sim::DecodeGroundTruth(e.data.data(), e.data.size(), log_path);
      const auto stamp = gt.stamp_ns;
      frames[stamp].truth = std::move(gt);
    } else if (e.channel == pi::kObstaclesChannel) {
      if (auto m = pi::DecodeObstacleList(e.data.data(), e.data.size(), nullptr)) frames[m->stamp_ns].obstacles = *m;
    } else if (e.channel == pi::kParkingSlotsChannel) {
      if (auto m = pi::DecodeParkingSlots(e.data.data(), e.data.size(), nullptr)) frames[m->stamp_ns].slots = *m;
    } else if (e.channel == objects::kPedestrianPredictionChannel) {
      auto preds = objects::DecodePedestrianPredictions(e.data.data(), e.data.size());
      if (!preds.empty()) frames[preds.front().stamp_ns].predictions = std::move(preds);
    }
  }
  const std::int64_t frames_before = out_.frames;
  calibrated_logs_ += calibration.has_value();
  objects::IdSwitchCounter switches(params_.car_match_m);  // track ids are per run
  std::set<std::pair<std::string, int>> seen_so_far;  // (class, truth id) visible in an earlier frame
  // Truth positions of pedestrians over time for prediction scoring (world frame).
  std::map<int, std::map<std::int64_t, Eigen::Vector2d>> ped_truth;
  for (const auto& [stamp, f] : frames) {
    if (!f.truth) continue;
    for (const auto& o : f.truth->objects) {
      if (o.class_name == "pedestrian") ped_truth[o.id][stamp] = o.center_m.head<2>();
    }
  }
  for (const auto& [stamp, f] : frames) {
    if (!f.truth || !f.obstacles) continue;
    ++out_.frames;
    const std::int64_t frame_index = out_.frames - 1 - frames_before;  // within this log
    const Eigen::Isometry3d& T_wv = f.truth->T_world_vehicle;
    const Eigen::Isometry3d T_vw = T_wv.inverse();
    std::vector<objects::IdPosition> gt_ids, track_ids;
    for (const std::string cls : {"car", "pedestrian"}) {
      std::vector<Eigen::Vector2d> truth, det;
      std::vector<int> truth_id, det_track;
      std::vector<bool> truth_visible;
      std::vector<double> truth_visible_fraction;
      std::vector<const sim::GtBox*> truth_box;
      std::vector<const pi::Obstacle*> det_box;
      // Objects up to a match gate past the range are matched too, so that a car straddling the
      // edge is neither a false detection (its truth just outside) nor a miss (its box just outside):
      // either pair is left unscored, like the objects beyond.
      const double gate = cls == "car" ? params_.car_match_m : params_.pedestrian_match_m;
      const double reach = params_.range_m + gate;
      for (const auto& o : f.truth->objects) {
        if (o.class_name != cls) continue;
        const Eigen::Vector2d v = (T_vw * o.center_m).head<2>();
        if (v.norm() > reach) continue;
        truth.push_back(v);
        truth_id.push_back(o.id);
        truth_box.push_back(&o);
        const double visible = calibration ? sim::VisibleFraction(o, f.truth->objects, *calibration, T_wv) : 0.0;
        truth_visible_fraction.push_back(visible);
        truth_visible.push_back(calibration && visible >= params_.min_visible_fraction);
      }
      for (const auto& o : f.obstacles->obstacles) {
        if (o.class_name != cls || o.center_m.head<2>().norm() > reach) continue;
        det.push_back(o.center_m.head<2>());
        det_track.push_back(o.track_id);
        det_box.push_back(&o);
      }
      std::vector<std::pair<int, int>> m = objects::MatchWithinGate(truth, det, gate);
      {
        // Scored: the truths within range, the detections matched to them, and the unmatched
        // detections within range.
        std::vector<int> det_truth(det.size(), -1);
        for (const auto& [i, j] : m) det_truth[static_cast<std::size_t>(j)] = i;
        std::vector<int> truth_index(truth.size(), -1), det_index(det.size(), -1);
        int kept = 0;
        for (std::size_t i = 0; i < truth.size(); ++i) {
          if (truth[i].norm() <= params_.range_m) truth_index[i] = kept++;
        }
        kept = 0;
        for (std::size_t j = 0; j < det.size(); ++j) {
          const int t = det_truth[j];
          if (t >= 0 ? truth_index[static_cast<std::size_t>(t)] >= 0 : det[j].norm() <= params_.range_m) det_index[j] = kept++;
        }
        std::vector<std::pair<int, int>> scored;
        for (const auto& [i, j] : m) {
          const int t = truth_index[static_cast<std::size_t>(i)];
          if (t >= 0) scored.emplace_back(t, det_index[static_cast<std::size_t>(j)]);
        }
        m = std::move(scored);
        Compact(&truth, truth_index);
        Compact(&truth_id, truth_index);
        Compact(&truth_box, truth_index);
        Compact(&truth_visible, truth_index);
        Compact(&truth_visible_fraction, truth_index);
        Compact(&det, det_index);
        Compact(&det_track, det_index);
        Compact(&det_box, det_index);
      }
      ClassScore& score = cls == "car" ? out_.car : out_.pedestrian;
      score.truths += static_cast<std::int64_t>(truth.size());
      score.detections += static_cast<std::int64_t>(det.size());
      score.matched_truths += static_cast<std::int64_t>(m.size());
      score.matched_detections += static_cast<std::int64_t>(m.size());
      if (calibration) {
        // Hidden truths are "don't care": neither a miss nor, when detected anyway, a false alarm.
        ClassScore& seen = cls == "car" ? out_.car_visible : out_.pedestrian_visible;
        std::int64_t matched_visible = 0, matched_hidden = 0;
        for (const auto& [i, j] : m) (truth_visible[i] ? matched_visible : matched_hidden) += 1;
        seen.truths += std::count(truth_visible.begin(), truth_visible.end(), true);
        seen.detections += static_cast<std::int64_t>(det.size()) - matched_hidden;
        seen.matched_truths += matched_visible;
        seen.matched_detections += matched_visible;
        std::vector<bool> matched(truth.size()), used(det.size());
        for (const auto& [i, j] : m) matched[i] = used[j] = true;
        HiddenScore& hidden = cls == "car" ? out_.car_hidden : out_.pedestrian_hidden;
        for (std::size_t i = 0; i < truth.size(); ++i) {
          if (truth_visible[i]) {
            seen_so_far.insert({cls, truth_id[i]});  // (a truth is listed once a frame: no other sighting of it here)
            continue;
          }
          const bool seen_before = seen_so_far.count({cls, truth_id[i]}) > 0;
          hidden.truths += 1;
          hidden.matched_truths += matched[i];
          hidden.seen_before += seen_before;
          hidden.seen_before_matched += seen_before && matched[i];
          if (seen_before && !matched[i]) {
            out_.hidden_misses.push_back(DescribeMiss(log_index, frame_index, cls, truth_id[i], truth[i],
                                                      HeadingIn(T_vw, truth_box[i]->yaw_rad),
                                                      truth_visible_fraction[i], f.obstacles->obstacles));
          }
        }
        for (std::size_t j = 0; j < det.size(); ++j) {
          if (used[j]) continue;
          out_.false_alarms.push_back(DescribeFalseAlarm(log_index, frame_index, cls, *det_box[j], f.truth->objects, T_vw));
        }
        for (std::size_t i = 0; i < truth.size(); ++i) {
          if (matched[i] || !truth_visible[i]) continue;
          out_.misses.push_back(DescribeMiss(log_index, frame_index, cls, truth_id[i], truth[i],
                                            HeadingIn(T_vw, truth_box[i]->yaw_rad), truth_visible_fraction[i],
                                            f.obstacles->obstacles));
        }
      }
      for (const auto& [i, j] : m) {
        center_errors_.push_back((truth[i] - det[j]).norm());
        (cls == "car" ? car_center_errors_ : pedestrian_center_errors_).push_back(center_errors_.back());
        const sim::GtBox& t = *truth_box[i];
        const pi::Obstacle& d = *det_box[j];
        size_errors_.push_back((t.size_m - d.size_m).norm());
        // Cars only: a pedestrian's footprint is too square for a heading.
        if (cls == "car") car_yaw_errors_.push_back(AxisAngleDeg(HeadingIn(T_vw, t.yaw_rad), d.yaw_rad));
      }
      for (std::size_t i = 0; i < truth.size(); ++i) gt_ids.push_back({truth_id[i], truth[i]});
      for (std::size_t j = 0; j < det.size(); ++j) {
        if (det_track[j] >= 0) track_ids.push_back({det_track[j], det[j]});
      }
    }
    switches.AddFrame(gt_ids, track_ids);

    // Predictions: each predicted point against the truth at the same future instant, in the
    // vehicle frame of the prediction's frame.
    for (const auto& p : f.predictions) {
      // The pedestrian this prediction is about: nearest truth to the observed position.
      int best = -1;
      double best_d = params_.pedestrian_match_m;
      for (const auto& o : f.truth->objects) {
        if (o.class_name != "pedestrian") continue;
        const double d = ((T_vw * o.center_m).head<2>() - p.observed.vehicle_xy_m).norm();
        if (d < best_d) {
          best_d = d;
          best = o.id;
        }
      }
      if (best < 0 || p.path.empty()) continue;
      const auto& trail = ped_truth[best];
      std::vector<double> errs;
      for (const auto& pt : p.path) {
        const std::int64_t t = p.observed_stamp_ns + static_cast<std::int64_t>(pt.dt_s * 1e9);
        auto it = trail.lower_bound(t - 60'000'000);
        if (it == trail.end() || std::llabs(it->first - t) > 60'000'000) {
          errs.clear();
          break;  // the horizon runs past the recording: not scored
        }
        const Eigen::Vector2d truth_v = (T_vw * Eigen::Vector3d(it->second.x(), it->second.y(), 0)).head<2>();
        errs.push_back((truth_v - pt.vehicle_xy_m).norm());
      }
      if (errs.empty()) continue;
      double sum = 0;
      for (double e : errs) sum += e;
      ade_list_.push_back(sum / errs.size());
      fde_list_.push_back(errs.back());
    }

    // Parking: the feasible bays fully visible now, and any narrow bay reported feasible.
    if (f.slots) {
      for (const auto& bay : f.truth->bays) {
        const Eigen::Vector2d bay_v = (T_vw * bay.center_m).head<2>();
        const pi::ParkingSlot* found = nullptr;
        double best = params_.slot_match_m;
        for (const auto& s : f.slots->slots) {
          const double d = (s.target.position_m - bay.center_m.head<2>()).norm();
          if (d < best) {
            best = d;
            found = &s;
          }
        }
        auto at_bay = [&](SceneBayAt* at) {
          at->log = log_index;
          at->frame = frame_index;
          at->bay_id = bay.id;
          at->x_m = bay_v.x();
          at->y_m = bay_v.y();
        };
        if (!bay.feasible) {
          if (found != nullptr && found->feasible) {
            SceneNarrowFeasible narrow;
            at_bay(&narrow);
            narrow.bay_width_m = bay.width_m;
            narrow.slot_length_m = found->length_m;
            narrow.prev_id = found->prev_id;
            narrow.next_id = found->next_id;
            narrow.confidence = found->confidence;
            out_.narrow_feasible.push_back(narrow);
          }
          continue;
        }
        if (bay_v.norm() > params_.bay_visible_range_m) continue;
        ++out_.slot_visible_frames;
        if (found != nullptr && found->feasible) {
          ++out_.slot_found_frames;
          slot_center_.push_back(best);
          slot_yaw_.push_back(AxisAngleDeg(found->target.yaw_rad, bay.yaw_rad));
        } else {
          SceneSlotMiss miss;
          at_bay(&miss);
          miss.slot_near = found != nullptr;
          miss.slot_m = found != nullptr ? best : 0.0;
          miss.slot_reason = found != nullptr ? found->reason : "";
          out_.slot_misses.push_back(miss);
        }
      }
    }
  }
  if (out_.frames == frames_before) {
    Fail("eval scene: " + log_path + " has no frame with both ground truth (" +
         sim::kGroundTruthChannel + ") and outputs (" + pi::kObstaclesChannel + ")");
  }
  ++out_.logs;
  out_.id_switches += switches.score().id_switches;
}

SceneEval Scorer::Finish() {
  SceneEval out = out_;
  out.range_m = params_.range_m;
  out.slot_match_m = params_.slot_match_m;
  // Visibility needs every log's calibration: scores over some of the logs would read as all.
  out.visibility_scored = out.logs > 0 && calibrated_logs_ == out.logs;
  if (!out.visibility_scored) {
    out.car_visible = out.pedestrian_visible = ClassScore{};
    out.car_hidden = out.pedestrian_hidden = HiddenScore{};
    out.misses.clear();
    out.hidden_misses.clear();
    out.false_alarms.clear();
  }
  out.box_center_err_m_median = Median(center_errors_);
  out.car.center_err_m_median = Median(car_center_errors_);
  out.pedestrian.center_err_m_median = Median(pedestrian_center_errors_);
  out.box_size_err_m_median = Median(size_errors_);
  out.car_yaw_err_deg_median = Median(car_yaw_errors_);
  out.predictions_scored = static_cast<std::int64_t>(ade_list_.size());
  for (double a : ade_list_) out.ade_m += a / ade_list_.size();
  for (double a : fde_list_) out.fde_m += a / fde_list_.size();
  out.slot_center_err_m = Median(slot_center_);
  out.slot_yaw_err_deg = Median(slot_yaw_);
  return out;
}


// "frame N", or "log K frame N" when several logs were pooled.
std::string Where(std::int64_t logs, int log, std::int64_t frame) {
  return (logs > 1 ? "log " + std::to_string(log) + " " : std::string()) + "frame " + std::to_string(frame);
}

// Counts as well as ratios, so that runs over several seeds can be pooled.
std::string ClassJson(const ClassScore& score, bool with_center) {
  std::ostringstream js;
  js.precision(4);
  js << "{\"precision\":" << score.precision() << ", \"recall\":" << score.recall();
  if (with_center) js << ", \"center_err_m_median\":" << score.center_err_m_median;
  js << ", \"truths\":" << score.truths << ", \"matched_truths\":" << score.matched_truths
     << ", \"detections\":" << score.detections << ", \"matched_detections\":" << score.matched_detections << "}";
  return js.str();
}

std::string HiddenJson(const HiddenScore& h) {
  std::ostringstream js;
  js << "{\"truths\":" << h.truths << ", \"matched_truths\":" << h.matched_truths << ", \"seen_before\":" << h.seen_before
     << ", \"seen_before_matched\":" << h.seen_before_matched << "}";
  return js.str();
}

std::string HiddenText(const HiddenScore& h) {
  std::ostringstream t;
  t << h.matched_truths << "/" << h.truths << " found (" << h.seen_before << " seen in an earlier frame, "
    << h.seen_before_matched << " of them found)";
  return t.str();
}

}  // namespace

SceneEval EvaluateSceneLogs(const std::vector<std::string>& log_paths, const SceneEvalParams& params) {
  if (log_paths.empty()) Fail("eval scene: no log given");
  Scorer scorer(params);
  for (std::size_t k = 0; k < log_paths.size(); ++k) scorer.Add(log_paths[k], static_cast<int>(k));
  return scorer.Finish();
}

SceneEval EvaluateSceneLog(const std::string& log_path, const SceneEvalParams& params) {
  return EvaluateSceneLogs({log_path}, params);
}


std::string SceneEval::ToJson() const {
  std::ostringstream js;
  js.precision(4);
  js << "{\"frames\":" << frames << ", \"logs\":" << logs << ", \"car\":" << ClassJson(car, true)
     << ", \"pedestrian\":" << ClassJson(pedestrian, true)
     << ", \"box_center_err_m_median\":" << box_center_err_m_median
     << ", \"box_size_err_m_median\":" << box_size_err_m_median
     << ", \"car_yaw_err_deg_median\":" << car_yaw_err_deg_median << ", \"id_switches\":" << id_switches << ", \"prediction\":{\"ade\":" << ade_m << ", \"fde\":" << fde_m
     << "}, \"slot\":{\"visible_frames\":" << slot_visible_frames << ", \"found_frames\":" << slot_found_frames
     << ", \"center_err_m\":" << slot_center_err_m << ", \"yaw_err_deg\":" << slot_yaw_err_deg
     << ", \"narrow_reported_feasible\":" << narrow_reported_feasible() << "}";
  if (visibility_scored) {
    js << ", \"car_visible\":" << ClassJson(car_visible, false)
       << ", \"pedestrian_visible\":" << ClassJson(pedestrian_visible, false)
       << ", \"car_hidden\":" << HiddenJson(car_hidden) << ", \"pedestrian_hidden\":" << HiddenJson(pedestrian_hidden);
  }
  js << "}";
  return js.str();
}

std::string SceneEval::ToText() const {
  std::ostringstream t;
  t.precision(3);
  t << "frames scored: " << frames << (logs > 1 ? " in " + std::to_string(logs) + " logs" : std::string()) << "\n"
    << "cars (<= " << range_m << " m):        precision " << car.precision() << "  recall " << car.recall() << "  ("
    << car.matched_truths << "/" << car.truths << " found, " << car.detections << " detections)\n"
    << "pedestrians (<= " << range_m << " m): precision " << pedestrian.precision() << "  recall " << pedestrian.recall()
    << "  (" << pedestrian.matched_truths << "/" << pedestrian.truths << " found, " << pedestrian.detections
    << " detections)\n"
    << (visibility_scored ? "" : "(no calibration in the log, or in one of the logs: objects hidden from the cameras count as misses)\n");
  if (visibility_scored) {
    t << "visible to the cameras: cars precision " << car_visible.precision() << "  recall " << car_visible.recall()
      << "  (" << car_visible.matched_truths << "/" << car_visible.truths << ");  pedestrians precision "
      << pedestrian_visible.precision() << "  recall " << pedestrian_visible.recall() << "  ("
      << pedestrian_visible.matched_truths << "/" << pedestrian_visible.truths << ")\n";
    t << "hidden from the cameras now: cars " << HiddenText(car_hidden) << ";  pedestrians "
      << HiddenText(pedestrian_hidden) << "\n";
  }
  t << "box errors (median): centre " << box_center_err_m_median << " m (cars " << car.center_err_m_median
    << ", pedestrians " << pedestrian.center_err_m_median << "), size " << box_size_err_m_median
    << " m, car yaw " << car_yaw_err_deg_median << " deg   ID switches: " << id_switches << "\n"
    << "pedestrian prediction:  ADE " << ade_m << " m  FDE " << fde_m << " m (" << predictions_scored
    << " predictions scored)\n"
    << "parking slot: found in " << slot_found_frames << "/" << slot_visible_frames
    << " frames where visible, centre error " << slot_center_err_m << " m, yaw error " << slot_yaw_err_deg
    << " deg; narrow bay reported feasible " << narrow_reported_feasible() << " times\n";
  return t.str();
}

std::string SceneEval::MissesText() const {
  std::ostringstream t;
  t.precision(3);
  auto list_misses = [&](const std::vector<SceneMiss>& list, const char* visibility) {
    for (const SceneMiss& m : list) {
      t << Where(logs, m.log, m.frame) << " " << m.class_name << " " << m.truth_id << " at (" << m.x_m << ", "
        << m.y_m << ") m, " << 100 * m.visible_fraction << visibility;
      if (m.nearest_class.empty()) {
        t << "nothing within 3 m\n";
      } else {
        t << "nearest " << m.nearest_class << " " << m.nearest_m << " m away (" << m.nearest_along_m << " along, "
          << m.nearest_across_m << " across its length), " << m.nearest_length_m << " x " << m.nearest_width_m
          << " x " << m.nearest_height_m << " m, yaw off " << m.nearest_yaw_err_deg << " deg, " << m.nearest_points
          << " points\n";
      }
    }
  };
  list_misses(misses, "% visible: ");
  list_misses(hidden_misses, "% visible, hidden now (seen before): ");
  for (const SceneFalseAlarm& a : false_alarms) {
    t << Where(logs, a.log, a.frame) << " false " << a.class_name << " at (" << a.x_m << ", " << a.y_m << ") m, "
      << a.length_m << " x " << a.width_m << " x " << a.height_m << " m, " << a.points
      << " points: nearest truth " << a.nearest_truth_class << " " << a.nearest_truth_id << " " << a.nearest_truth_m
      << " m away";
    if (a.inside_truth_id >= 0) t << ", inside " << a.inside_truth_class << " " << a.inside_truth_id;
    t << "\n";
  }
  for (const SceneSlotMiss& m : slot_misses) {
    t << Where(logs, m.log, m.frame) << " bay " << m.bay_id << " at (" << m.x_m << ", " << m.y_m << ") m not found: ";
    if (m.slot_near) {
      t << "the slot " << m.slot_m << " m from it infeasible (" << m.slot_reason << ")\n";
    } else {
      t << "no slot within " << slot_match_m << " m\n";
    }
  }
  for (const SceneNarrowFeasible& n : narrow_feasible) {
    t << Where(logs, n.log, n.frame) << " narrow bay " << n.bay_id << " at (" << n.x_m << ", " << n.y_m << ") m, "
      << n.bay_width_m << " m wide, reported feasible: a slot " << n.slot_length_m << " m long between tracks "
      << n.prev_id << " and " << n.next_id << ", confidence " << n.confidence << "\n";
  }
  return t.str();
}

}  // namespace romo::pipeline
