#include "romo/objects/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "romo/core/check.hpp"
#include "romo/objects/hungarian.hpp"

namespace romo::objects {
namespace {

using Vec4 = Eigen::Matrix<double, 4, 1>;
using Mat4 = Eigen::Matrix<double, 4, 4>;
using Mat24 = Eigen::Matrix<double, 2, 4>;

Mat24 H() {
  Mat24 h = Mat24::Zero();
  h(0, 0) = 1.0;
  h(1, 1) = 1.0;
  return h;
}

Eigen::Matrix2d Rotation(double yaw_rad) {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

struct TrackState_ {
  Track track;
  Vec4 x = Vec4::Zero();
  Mat4 P = Mat4::Zero();
  std::unique_ptr<PathPredictor> predictor;
  int misses = 0;
  Eigen::Vector2d companion_offset = Eigen::Vector2d::Zero();  // from the companion, when lost
  // Last placed by a measured companion: as good as seen then, so its own coast starts there.
  double placed_s = -std::numeric_limits<double>::infinity();
  bool duplicate = false;  // a follower where another track measures someone: that person (ends)
  std::vector<int> votes;         // per Atlas class
  std::vector<double> vote_score;  // summed scores per class
};

}  // namespace

Detection Detection::FromBox(const Box3& box, const Atlas& atlas) {
  return FromBox(box, atlas.Classify(box));
}

Detection Detection::FromBox(const Box3& box, const Classification& classification) {
  Detection d;
  d.xy_m = box.center.head<2>().cast<double>();
  d.yaw_rad = box.yaw_rad;
  d.length_m = std::max(box.size.x(), box.size.y());
  d.width_m = std::min(box.size.x(), box.size.y());
  d.height_m = box.size.z();
  d.classification = classification;
  return d;
}

const char* ToString(TrackState state) {
  switch (state) {
    case TrackState::kTentative: return "tentative";
    case TrackState::kConfirmed: return "confirmed";
    case TrackState::kLost: return "lost";
  }
  return "?";
}

void TrackerParams::Validate() const {
  auto bad = [](const char* field, double value, const char* expected) {
    std::ostringstream m;
    m << "TrackerParams." << field << " = " << value << " is invalid (" << expected << ")";
    Fail(m.str());
  };
  if (!(measurement_sigma_m > 0.0)) bad("measurement_sigma_m", measurement_sigma_m, "need > 0");
  if (!(accel_sigma_mps2 > 0.0)) bad("accel_sigma_mps2", accel_sigma_mps2, "need > 0");
  if (!(initial_speed_sigma_mps > 0.0)) bad("initial_speed_sigma_mps", initial_speed_sigma_mps, "need > 0");
  if (!(gate_chi2 > 0.0)) bad("gate_chi2", gate_chi2, "need > 0");
  if (confirm_hits < 1) bad("confirm_hits", confirm_hits, "need >= 1");
  if (tentative_max_misses < 0) bad("tentative_max_misses", tentative_max_misses, "need >= 0");
  if (!(max_occlusion_s >= 0.0)) bad("max_occlusion_s", max_occlusion_s, "need >= 0");
  if (max_tracks_per_blob < 1) bad("max_tracks_per_blob", max_tracks_per_blob, "need >= 1");
  if (!(merged_inset_m >= 0.0)) bad("merged_inset_m", merged_inset_m, "need >= 0");
  if (!(merged_sigma_m > 0.0)) bad("merged_sigma_m", merged_sigma_m, "need > 0");
  if (!(companion_max_gap_m >= 0.0)) bad("companion_max_gap_m", companion_max_gap_m, "need >= 0 (0 = off)");
  if (!(companion_min_speed_mps >= 0.0)) bad("companion_min_speed_mps", companion_min_speed_mps, "need >= 0");
  if (!(companion_max_speed_diff_mps >= 0.0)) {
    bad("companion_max_speed_diff_mps", companion_max_speed_diff_mps, "need >= 0");
  }
  if (!(companion_max_occlusion_s >= 0.0)) bad("companion_max_occlusion_s", companion_max_occlusion_s, "need >= 0");
  if (!(companion_standing_min_gap_m >= 0.0)) {
    bad("companion_standing_min_gap_m", companion_standing_min_gap_m, "need >= 0");
  }
  predictor.Validate();
}

class Tracker::Impl {
 public:
  Impl(const Atlas& atlas, const TrackerParams& params) : atlas_(atlas), params_(params) {
    params_.Validate();
    pedestrian_ = atlas_.Require("pedestrian");
  }

  const std::vector<Track>& Update(double stamp_s, const std::vector<Detection>& detections);
  std::optional<double> YawHint(const Eigen::Vector2d& xy_m) const;

  Atlas atlas_;
  TrackerParams params_;
  int pedestrian_ = -1;
  bool started_ = false;
  double stamp_s_ = 0.0;
  int next_id_ = 1;
  int created_ = 0;
  int deleted_ = 0;
  std::vector<TrackState_> states_;
  std::vector<Track> snapshot_;

 private:
  void Predict(TrackState_* s, double dt) const;
  void KalmanUpdate(TrackState_* s, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) const;
  bool MayHoldSeveral(const Detection& d) const;
  Eigen::Matrix2d MeasurementCov(const Detection& d) const;
  bool Glimpse(const TrackState_& s, const Detection& d) const;
  void ReservePeopleForPedestrianTracks(const std::vector<Detection>& detections,
                                        const std::vector<int>& column_detection, Eigen::MatrixXd* cost) const;
  bool WithinCompanionGap(const TrackState_& s, const Eigen::Vector2d& xy_m) const;
  std::size_t IndexOf(int track_id) const;  // into states_; states_.size() when gone
  Eigen::Matrix2d GlimpseCov() const;
  bool OccludedTooLong(const TrackState_& s, double stamp_s) const;
  void FollowCompanions(const std::vector<char>& updated, const std::vector<char>& glimpsed, double stamp_s);
  void Observe(TrackState_* s, const Detection& d, double stamp_s, bool glimpse = false) const;
};

void Tracker::Impl::Predict(TrackState_* s, double dt) const {
  Mat4 F = Mat4::Identity();
  F(0, 2) = dt;
  F(1, 3) = dt;
  // White-noise acceleration, per axis [[dt^4/4, dt^3/2], [dt^3/2, dt^2]] * sigma_a^2.
  const double q = params_.accel_sigma_mps2 * params_.accel_sigma_mps2;
  const double dt2 = dt * dt, dt3 = dt2 * dt, dt4 = dt3 * dt;
  Mat4 Q = Mat4::Zero();
  for (int a = 0; a < 2; ++a) {
    Q(a, a) = q * dt4 / 4.0;
    Q(a, a + 2) = Q(a + 2, a) = q * dt3 / 2.0;
    Q(a + 2, a + 2) = q * dt2;
  }
  s->x = F * s->x;
  s->P = F * s->P * F.transpose() + Q;
}

void Tracker::Impl::KalmanUpdate(TrackState_* s, const Eigen::Vector2d& z,
                                 const Eigen::Matrix2d& R) const {
  const Mat24 h = H();
  const Eigen::Matrix2d S = h * s->P * h.transpose() + R;
  const Eigen::Matrix<double, 4, 2> K = s->P * h.transpose() * S.inverse();
  s->x += K * (z - h * s->x);
  // Joseph form: stays symmetric positive definite over long coasts.
  const Mat4 I_KH = Mat4::Identity() - K * h;
  s->P = I_KH * s->P * I_KH.transpose() + K * R * K.transpose();
}

bool Tracker::Impl::MayHoldSeveral(const Detection& d) const {
  if (params_.max_tracks_per_blob < 2) return false;
  const ObjectClass& ped = atlas_.classes()[static_cast<std::size_t>(pedestrian_)];
  // Pedestrian-tall, a footprint longer than a typical single pedestrian (mean + 1 sigma: two
  // people side by side) and not beyond a small group. A lone long pedestrian blob only gets a
  // wider measurement spread from this; sharing needs a second pedestrian track in its gate.
  return ped.height.Contains(d.height_m) && d.length_m > ped.length.mean_m + ped.length.sigma_m &&
         d.length_m <= params_.max_tracks_per_blob * ped.length.max_m;
}

Eigen::Matrix2d Tracker::Impl::MeasurementCov(const Detection& d) const {
  const double s2 = params_.measurement_sigma_m * params_.measurement_sigma_m;
  if (!MayHoldSeveral(d)) return Eigen::Matrix2d::Identity() * s2;
  // A member of a merged blob lies anywhere in its footprint: uniform spread l^2/12, w^2/12.
  const Eigen::Matrix2d r = Rotation(d.yaw_rad);
  const Eigen::Vector2d spread(d.length_m * d.length_m / 12.0 + s2, d.width_m * d.width_m / 12.0 + s2);
  return r * spread.asDiagonal() * r.transpose();
}

bool Tracker::Impl::Glimpse(const TrackState_& s, const Detection& d) const {
  if (!params_.companion_glimpses || s.track.companion_id < 0) return false;
  const ObjectClass& ped = atlas_.classes()[static_cast<std::size_t>(pedestrian_)];
  return d.classification.class_index != pedestrian_ || d.width_m < ped.width.mean_m - ped.width.sigma_m;
}

// A track of another class moving faster than anyone walks is no person's: gating a person's
// detection it would take it, and leave the person's own track a worse one.
void Tracker::Impl::ReservePeopleForPedestrianTracks(const std::vector<Detection>& detections,
                                                     const std::vector<int>& column_detection,
                                                     Eigen::MatrixXd* cost) const {
  if (!params_.people_for_pedestrian_tracks) return;
  const double walking_limit = atlas_.classes()[static_cast<std::size_t>(pedestrian_)].max_speed_mps;
  std::vector<Eigen::Index> no_person;  // rows of tracks of another class, faster than a walker
  for (std::size_t i = 0; i < states_.size(); ++i) {
    const TrackState_& s = states_[i];
    if (s.track.class_index != pedestrian_ && s.x.tail<2>().norm() > walking_limit) {
      no_person.push_back(static_cast<Eigen::Index>(i));
    }
  }
  if (no_person.empty()) return;
  for (Eigen::Index c = 0; c < cost->cols(); ++c) {
    if (detections[static_cast<std::size_t>(column_detection[static_cast<std::size_t>(c)])].classification.class_index !=
        pedestrian_) {
      continue;
    }
    bool person_gates = false;
    for (std::size_t i = 0; i < states_.size(); ++i) {
      const Track& t = states_[i].track;
      person_gates |= t.class_index == pedestrian_ && t.state != TrackState::kTentative &&
                      (*cost)(static_cast<Eigen::Index>(i), c) < kForbiddenCost;
    }
    if (!person_gates) continue;
    for (Eigen::Index i : no_person) (*cost)(i, c) = kForbiddenCost;
  }
}

std::size_t Tracker::Impl::IndexOf(int track_id) const {
  std::size_t k = 0;
  while (k < states_.size() && states_[k].track.id != track_id) ++k;
  return k;
}

bool Tracker::Impl::WithinCompanionGap(const TrackState_& s, const Eigen::Vector2d& xy_m) const {
  const std::size_t c = IndexOf(s.track.companion_id);
  return c == states_.size() || (xy_m - states_[c].x.head<2>()).norm() <= params_.companion_max_gap_m;
}

Eigen::Matrix2d Tracker::Impl::GlimpseCov() const {
  const ObjectClass& ped = atlas_.classes()[static_cast<std::size_t>(pedestrian_)];
  const double s2 = params_.measurement_sigma_m * params_.measurement_sigma_m;
  return Eigen::Matrix2d::Identity() * (ped.length.max_m * ped.length.max_m / 12.0 + s2);
}

bool Tracker::Impl::OccludedTooLong(const TrackState_& s, double stamp_s) const {
  double limit = params_.max_occlusion_s;
  if (s.track.class_index >= 0) {
    limit = std::max(limit, atlas_.classes()[static_cast<std::size_t>(s.track.class_index)].max_occlusion_s);
  }
  // Placed by its companion this frame (FollowCompanions): bounded since it was seen itself. Alone
  // again (its companion's track ended), it coasts from where a measured companion last placed it.
  if (s.track.companion_id >= 0) {
    return stamp_s - s.track.last_seen_s > std::max(limit, params_.companion_max_occlusion_s);
  }
  return stamp_s - std::max(s.track.last_seen_s, s.placed_s) > limit;
}

void Tracker::Impl::FollowCompanions(const std::vector<char>& updated, const std::vector<char>& glimpsed,
                                     double stamp_s) {
  // Companions: pedestrian tracks measured alone now. A companion is taken only while walking (two
  // people standing near each other need not be together), then followed while it stands too:
  // people walking together stop together, and the hidden one waits behind the one seen. Hidden
  // too, the companion is followed as it coasts: the two walk on together, and when it is seen
  // again the follower is placed beside it again.
  auto walks = [&](const TrackState_& c) { return c.x.tail<2>().norm() >= params_.companion_min_speed_mps; };
  auto measured = [&](std::size_t k) {
    const TrackState_& c = states_[k];
    return updated[k] && !c.track.merged && c.track.class_index == pedestrian_;
  };
  for (std::size_t i = 0; i < states_.size(); ++i) {
    TrackState_& s = states_[i];
    Track& t = s.track;
    if (glimpsed[i]) {
      // Moved by the glimpse, it walks on with its companion from there.
      const std::size_t c = IndexOf(t.companion_id);
      if (c == states_.size()) {
        t.companion_id = -1;
      } else {
        s.x.tail<2>() = states_[c].x.tail<2>();
        s.companion_offset = s.x.head<2>() - states_[c].x.head<2>();
      }
      continue;
    }
    if (updated[i] || t.state == TrackState::kTentative || t.class_index != pedestrian_) {
      t.companion_id = -1;
      continue;
    }
    if (t.companion_id < 0 && s.misses == 0) {
      // Lost just now: the nearest walker beside it moving alike (the predictions still agree).
      double best = params_.companion_max_gap_m;
      for (std::size_t k = 0; k < states_.size(); ++k) {
        const TrackState_& c = states_[k];
        if (!measured(k) || !walks(c)) continue;
        const double gap = (s.x.head<2>() - c.x.head<2>()).norm();
        if (gap <= best && (s.x.tail<2>() - c.x.tail<2>()).norm() <= params_.companion_max_speed_diff_mps) {
          best = gap;
          t.companion_id = c.track.id;
          s.companion_offset = s.x.head<2>() - c.x.head<2>();
        }
      }
    }
    if (t.companion_id < 0) continue;
    const std::size_t c = IndexOf(t.companion_id);
    // (Standing close by, the two are as likely one person tracked twice, sharing one blob.)
    const bool stands_close = c < states_.size() && measured(c) && !walks(states_[c]) &&
                              s.companion_offset.norm() < params_.companion_standing_min_gap_m;
    if (c == states_.size() || stands_close) {
      // The companion's track ended: coast alone from where it last placed it. Or it stands close
      // by: as likely its duplicate, it coasts from where it was last seen.
      t.companion_id = -1;
      if (stands_close) s.placed_s = -std::numeric_limits<double>::infinity();
      continue;
    }
    const TrackState_& companion = states_[c];
    s.x.head<2>() = companion.x.head<2>() + s.companion_offset;
    s.x.tail<2>() = companion.x.tail<2>();
    s.P = companion.P;
    if (measured(c)) s.placed_s = stamp_s;
  }
  // A follower nearer another person measured now than two people stand apart is that person,
  // tracked twice.
  for (std::size_t i = 0; i < states_.size(); ++i) {
    TrackState_& s = states_[i];
    if (s.track.companion_id < 0) continue;
    for (std::size_t k = 0; k < states_.size(); ++k) {
      if (k == i || glimpsed[k] || !measured(k) || states_[k].track.id == s.track.companion_id) continue;
      if ((s.x.head<2>() - states_[k].x.head<2>()).norm() < params_.companion_standing_min_gap_m) s.duplicate = true;
    }
  }
}

void Tracker::Impl::Observe(TrackState_* s, const Detection& d, double stamp_s, bool glimpse) const {
  Track& t = s->track;
  const int c = d.classification.class_index;
  // A glimpse (a sliver of a follower hidden in part) says where the person is, not what: its
  // class is the part's, and a few of them would outvote the person.
  if (!glimpse && c >= 0 && c < static_cast<int>(s->votes.size())) {
    ++s->votes[static_cast<std::size_t>(c)];
    s->vote_score[static_cast<std::size_t>(c)] += d.classification.score;
    // Majority of the votes; a real class beats "unknown" on a tie.
    int best = t.class_index;
    for (int k = 0; k < static_cast<int>(s->votes.size()); ++k) {
      const int vk = s->votes[static_cast<std::size_t>(k)];
      const int vb = best >= 0 ? s->votes[static_cast<std::size_t>(best)] : -1;
      if (vk > vb || (vk == vb && best == atlas_.unknown_index() && k != best)) best = k;
    }
    t.class_index = best;
    t.class_score = s->vote_score[static_cast<std::size_t>(best)] /
                    std::max(1, s->votes[static_cast<std::size_t>(best)]);
  }
  float length = static_cast<float>(d.length_m), width = static_cast<float>(d.width_m);
  if (t.hits > 0) {
    // Heading continuity: the equivalent heading (mod pi) nearest the track's.
    t.yaw_rad = CanonicalYaw(static_cast<float>(d.yaw_rad), &length, &width,
                             static_cast<float>(t.yaw_rad));
  } else {
    t.yaw_rad = d.yaw_rad;
  }
  t.length_m = length;
  t.width_m = width;
  t.height_m = d.height_m;
  s->predictor->Update(stamp_s, d.xy_m);
  t.observed_xy_m = d.xy_m;
  t.observed_s = stamp_s;
  const bool predict = t.class_index >= 0 &&
                       atlas_.classes()[static_cast<std::size_t>(t.class_index)].predict_path;
  if (predict) {
    t.predicted_path = s->predictor->PredictHorizon();
  } else {
    t.predicted_path.clear();
  }
}

const std::vector<Track>& Tracker::Impl::Update(double stamp_s,
                                                const std::vector<Detection>& detections) {
  if (!std::isfinite(stamp_s) || (started_ && !(stamp_s > stamp_s_))) {
    std::ostringstream m;
    m << "Tracker::Update: stamp " << stamp_s << " s does not follow the previous " << stamp_s_
      << " s";
    Fail(m.str());
  }
  for (std::size_t j = 0; j < detections.size(); ++j) {
    const Detection& d = detections[j];
    if (!d.xy_m.allFinite() || !std::isfinite(d.yaw_rad) || !std::isfinite(d.length_m) ||
        !std::isfinite(d.width_m) || !std::isfinite(d.height_m)) {
      Fail("Tracker::Update: detection " + std::to_string(j) + " has a non-finite value");
    }
  }
  const double dt = started_ ? stamp_s - stamp_s_ : 0.0;
  started_ = true;
  stamp_s_ = stamp_s;
  for (auto& s : states_) Predict(&s, dt);

  // Columns: one per detection, plus extra copies of blobs that may hold several pedestrians.
  std::vector<int> column_detection;
  std::vector<int> column_copy;
  for (std::size_t j = 0; j < detections.size(); ++j) {
    const int copies = MayHoldSeveral(detections[j]) ? params_.max_tracks_per_blob : 1;
    for (int k = 0; k < copies; ++k) {
      column_detection.push_back(static_cast<int>(j));
      column_copy.push_back(k);
    }
  }
  std::vector<Eigen::Matrix2d> R(detections.size());
  for (std::size_t j = 0; j < detections.size(); ++j) R[j] = MeasurementCov(detections[j]);

  const Mat24 h = H();
  Eigen::MatrixXd cost(static_cast<Eigen::Index>(states_.size()),
                       static_cast<Eigen::Index>(column_detection.size()));
  for (std::size_t i = 0; i < states_.size(); ++i) {
    const TrackState_& s = states_[i];
    const bool pedestrian_track = s.track.class_index == pedestrian_;
    for (std::size_t c = 0; c < column_detection.size(); ++c) {
      const int j = column_detection[c];
      double value = kForbiddenCost;
      // People walking together stay together: a glimpse farther from the companion is someone else.
      const bool allowed = !Glimpse(s, detections[static_cast<std::size_t>(j)]) ||
                           WithinCompanionGap(s, detections[static_cast<std::size_t>(j)].xy_m);
      if (allowed && (column_copy[c] == 0 || pedestrian_track)) {
        const Eigen::Matrix2d S = h * s.P * h.transpose() + R[static_cast<std::size_t>(j)];
        const Eigen::Vector2d y = detections[static_cast<std::size_t>(j)].xy_m - h * s.x;
        const double d2 = y.dot(S.ldlt().solve(y));
        // The log-determinant keeps a wide (coasting) track from stealing a detection that a
        // tight track explains just as well.
        if (d2 <= params_.gate_chi2) value = d2 + std::log(S.determinant());
      }
      cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = value;
    }
  }
  ReservePeopleForPedestrianTracks(detections, column_detection, &cost);
  const Assignment assignment = SolveAssignment(cost);

  std::vector<std::vector<int>> members(detections.size());
  for (std::size_t i = 0; i < states_.size(); ++i) {
    const int c = assignment.row_to_col[i];
    if (c >= 0) members[static_cast<std::size_t>(column_detection[static_cast<std::size_t>(c)])].push_back(static_cast<int>(i));
  }
  std::vector<char> updated(states_.size(), 0), glimpsed(states_.size(), 0);
  for (std::size_t j = 0; j < detections.size(); ++j) {
    const Detection& d = detections[j];
    if (members[j].size() == 1) {
      TrackState_& s = states_[static_cast<std::size_t>(members[j][0])];
      const bool glimpse = Glimpse(s, d);
      glimpsed[static_cast<std::size_t>(members[j][0])] = glimpse ? 1 : 0;
      KalmanUpdate(&s, d.xy_m, glimpse ? GlimpseCov() : R[j]);
      Observe(&s, d, stamp_s, glimpse);
      s.track.merged = false;
      s.track.detection_index = static_cast<int>(j);
      updated[static_cast<std::size_t>(members[j][0])] = 1;
    } else if (members[j].size() > 1) {
      // Partial occlusion: the members stand side by side along the blob's long axis, in the
      // order of their predicted positions (so identities cannot swap inside the blob), evenly
      // spaced with their centres merged_inset_m inside the ends. The blob centre is nobody's
      // position, so no trail point and no class vote.
      const Eigen::Matrix2d rot = Rotation(d.yaw_rad);
      const double half_l = std::max(0.0, d.length_m / 2.0 - params_.merged_inset_m);
      const double half_w = std::max(0.0, d.width_m / 2.0 - params_.merged_inset_m);
      const Eigen::Matrix2d Rm = Eigen::Matrix2d::Identity() * params_.merged_sigma_m * params_.merged_sigma_m;
      std::vector<std::pair<double, int>> order;  // (along-axis predicted offset, track)
      for (int i : members[j]) {
        const Eigen::Vector2d local = rot.transpose() * (states_[static_cast<std::size_t>(i)].x.head<2>() - d.xy_m);
        order.emplace_back(local.x(), i);
      }
      std::sort(order.begin(), order.end());
      const int k = static_cast<int>(order.size());
      for (int slot = 0; slot < k; ++slot) {
        const int i = order[static_cast<std::size_t>(slot)].second;
        TrackState_& s = states_[static_cast<std::size_t>(i)];
        Eigen::Vector2d local = rot.transpose() * (s.x.head<2>() - d.xy_m);
        local.x() = -half_l + 2.0 * half_l * slot / (k - 1);
        local.y() = std::clamp(local.y(), -half_w, half_w);
        KalmanUpdate(&s, d.xy_m + rot * local, Rm);
        s.track.merged = true;
        s.track.detection_index = static_cast<int>(j);
        updated[static_cast<std::size_t>(i)] = 1;
      }
    }
  }

  if (params_.companion_max_gap_m > 0.0) FollowCompanions(updated, glimpsed, stamp_s);

  // Lifecycle of every existing track.
  std::vector<TrackState_> kept;
  kept.reserve(states_.size() + detections.size());
  for (std::size_t i = 0; i < states_.size(); ++i) {
    TrackState_& s = states_[i];
    Track& t = s.track;
    if (s.duplicate) {
      ++deleted_;
      continue;
    }
    if (updated[i]) {
      ++t.hits;
      s.misses = 0;
      t.last_seen_s = stamp_s;
      if (t.state == TrackState::kLost || t.hits >= params_.confirm_hits) t.state = TrackState::kConfirmed;
    } else {
      ++s.misses;
      t.merged = false;
      t.detection_index = -1;
      if (t.state == TrackState::kTentative) {
        if (s.misses > params_.tentative_max_misses) {
          ++deleted_;
          continue;
        }
      } else {
        t.state = TrackState::kLost;
        if (OccludedTooLong(s, stamp_s)) {
          ++deleted_;
          continue;
        }
      }
    }
    kept.push_back(std::move(s));
  }
  // New tentative tracks from detections nobody took.
  const double sv2 = params_.initial_speed_sigma_mps * params_.initial_speed_sigma_mps;
  const double sp2 = params_.measurement_sigma_m * params_.measurement_sigma_m;
  for (std::size_t j = 0; j < detections.size(); ++j) {
    if (!members[j].empty()) continue;
    TrackState_ s;
    s.x << detections[j].xy_m, 0.0, 0.0;
    s.P.diagonal() << sp2, sp2, sv2, sv2;
    s.votes.assign(atlas_.classes().size(), 0);
    s.vote_score.assign(atlas_.classes().size(), 0.0);
    s.predictor = MakePathPredictor(params_.predictor);
    s.track.id = next_id_++;
    s.track.first_seen_s = stamp_s;
    s.track.last_seen_s = stamp_s;
    s.track.detection_index = static_cast<int>(j);
    s.track.state = params_.confirm_hits <= 1 ? TrackState::kConfirmed : TrackState::kTentative;
    Observe(&s, detections[j], stamp_s);  // hits == 0 here: the first yaw is taken as measured
    s.track.hits = 1;
    ++created_;
    kept.push_back(std::move(s));
  }
  states_ = std::move(kept);

  snapshot_.clear();
  snapshot_.reserve(states_.size());
  for (auto& s : states_) {
    s.track.xy_m = s.x.head<2>();
    s.track.velocity_mps = s.x.tail<2>();
    s.track.position_cov_m2 = s.P.topLeftCorner<2, 2>();
    s.track.velocity_cov_m2ps2 = s.P.bottomRightCorner<2, 2>();
    snapshot_.push_back(s.track);
  }
  return snapshot_;
}

std::optional<double> Tracker::Impl::YawHint(const Eigen::Vector2d& xy_m) const {
  std::optional<double> best;
  double best_d2 = params_.gate_chi2;
  const Mat24 h = H();
  const double s2 = params_.measurement_sigma_m * params_.measurement_sigma_m;
  for (const auto& s : states_) {
    if (s.track.hits == 0) continue;
    const Eigen::Matrix2d S = h * s.P * h.transpose() + Eigen::Matrix2d::Identity() * s2;
    const Eigen::Vector2d y = xy_m - h * s.x;
    const double d2 = y.dot(S.ldlt().solve(y));
    if (d2 <= best_d2) {
      best_d2 = d2;
      best = s.track.yaw_rad;
    }
  }
  return best;
}

Tracker::Tracker(const Atlas& atlas, const TrackerParams& params)
    : impl_(std::make_unique<Impl>(atlas, params)) {}
Tracker::~Tracker() = default;
Tracker::Tracker(Tracker&&) noexcept = default;
Tracker& Tracker::operator=(Tracker&&) noexcept = default;

const std::vector<Track>& Tracker::Update(double stamp_s, const std::vector<Detection>& detections) {
  return impl_->Update(stamp_s, detections);
}
const std::vector<Track>& Tracker::tracks() const { return impl_->snapshot_; }
std::optional<double> Tracker::YawHint(const Eigen::Vector2d& xy_m) const {
  return impl_->YawHint(xy_m);
}
const Atlas& Tracker::atlas() const { return impl_->atlas_; }
const TrackerParams& Tracker::params() const { return impl_->params_; }
int Tracker::tracks_created() const { return impl_->created_; }
int Tracker::tracks_deleted() const { return impl_->deleted_; }

}  // namespace romo::objects
