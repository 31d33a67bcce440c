#include "romo/planning_iface/parking_slot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "romo/core/check.hpp"

namespace romo::planning_iface {
namespace {

constexpr double kPi = 3.14159265358979323846;

using Corners = std::array<Eigen::Vector2d, 4>;

Eigen::Vector2d Dir(double yaw) { return {std::cos(yaw), std::sin(yaw)}; }
Eigen::Vector2d Perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }

Corners CornersOf(const GroundBox& b) {
  const Eigen::Vector2d a = Dir(b.yaw_rad) * (b.length_m / 2);
  const Eigen::Vector2d p = Perp(Dir(b.yaw_rad)) * (b.width_m / 2);
  return {b.center_m + a + p, b.center_m - a + p, b.center_m - a - p, b.center_m + a - p};
}

// Separating-axis test on the four edge normals of two rectangles.
bool Overlap(const Corners& a, const Corners& b) {
  for (const Corners* poly : {&a, &b}) {
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector2d axis = Perp((*poly)[e + 1] - (*poly)[e]);
      double amin = std::numeric_limits<double>::infinity(), amax = -amin;
      double bmin = amin, bmax = -amin;
      for (const auto& c : a) {
        amin = std::min(amin, c.dot(axis));
        amax = std::max(amax, c.dot(axis));
      }
      for (const auto& c : b) {
        bmin = std::min(bmin, c.dot(axis));
        bmax = std::max(bmax, c.dot(axis));
      }
      if (amax < bmin || bmax < amin) return false;
    }
  }
  return true;
}

double PointSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& s0, const Eigen::Vector2d& s1) {
  const Eigen::Vector2d d = s1 - s0;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - s0).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (s0 + t * d - p).norm();
}

// Half extents of a box along the unit axis u and across it.
double HalfExtentAlong(const GroundBox& b, const Eigen::Vector2d& u) {
  const Eigen::Vector2d a = Dir(b.yaw_rad);
  return std::abs(a.dot(u)) * b.length_m / 2 + std::abs(Perp(a).dot(u)) * b.width_m / 2;
}

// Of the two headings along an axis, the one closer to @p reference (ties: @p axis_yaw itself).
double HeadingAlong(double axis_yaw, double reference) {
  return WrapAngle(std::abs(WrapAngle(reference - axis_yaw)) > kPi / 2 + 1e-12 ? axis_yaw + kPi
                                                                             : axis_yaw);
}

// Difference of two headings modulo 180 degrees, in (-pi/2, pi/2].
double AxisDiff(double a, double b) {
  double d = WrapAngle(a - b);
  if (d > kPi / 2) d -= kPi;
  if (d <= -kPi / 2) d += kPi;
  return d;
}

// A box that overlaps a neighbour is that neighbour (seen again, or seen by two rigs).
bool IsNeighbour(const GroundBox& car, const ParkingSlot& slot) {
  return FootprintDistance(car, slot.prev_box) == 0.0 || FootprintDistance(car, slot.next_box) == 0.0;
}

void CheckBox(const GroundBox& b, std::size_t index) {
  if (!b.center_m.allFinite() || !std::isfinite(b.yaw_rad) || !std::isfinite(b.length_m) ||
      !std::isfinite(b.width_m) || b.length_m <= 0 || b.width_m <= 0) {
    std::ostringstream os;
    os << "parking: car box " << index << " (id " << b.id << ") is invalid: centre ("
       << b.center_m.x() << ", " << b.center_m.y() << ") yaw " << b.yaw_rad << " size "
       << b.length_m << " x " << b.width_m;
    Fail(os.str());
  }
}

struct PairGap {
  int i, j;  // i before j along u
  Eigen::Vector2d u;
  double start, end;  // along u
};

// Gaps between cars i and j along axis mode (0: along the cars' length, 1: across it).
std::optional<PairGap> GapAlong(const std::vector<GroundBox>& cars, int i, int j, int mode,
                                const ParkingParams& params) {
  const Eigen::Vector2d a = Dir(cars[i].yaw_rad);
  Eigen::Vector2d u = mode == 0 ? a : Perp(a);
  const Eigen::Vector2d d = cars[j].center_m - cars[i].center_m;
  if (d.dot(u) < 0) {
    u = -u;
  }
  const Eigen::Vector2d n = Perp(u);
  if (std::abs(d.dot(n)) > params.row_lateral_tolerance_m) return std::nullopt;
  const double start = cars[i].center_m.dot(u) + HalfExtentAlong(cars[i], u);
  const double end = cars[j].center_m.dot(u) - HalfExtentAlong(cars[j], u);
  return PairGap{i, j, u, start, end};
}

}  // namespace

double WrapAngle(double rad) {
  double r = std::fmod(rad + kPi, 2 * kPi);
  if (r <= 0) r += 2 * kPi;
  return r - kPi;
}

void ParkingParams::Validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) {
      Fail(std::string("ParkingParams.") + name + " must be > 0, got " + std::to_string(v));
    }
  };
  auto non_negative = [](double v, const char* name) {
    if (!(v >= 0) || !std::isfinite(v)) {
      Fail(std::string("ParkingParams.") + name + " must be >= 0, got " + std::to_string(v));
    }
  };
  positive(ego_length_m, "ego_length_m");
  positive(ego_width_m, "ego_width_m");
  non_negative(end_margin_m, "end_margin_m");
  non_negative(min_clearance_m, "min_clearance_m");
  non_negative(turn_clearance_m, "turn_clearance_m");
  positive(row_yaw_tolerance_rad, "row_yaw_tolerance_rad");
  positive(row_lateral_tolerance_m, "row_lateral_tolerance_m");
  non_negative(min_gap_m, "min_gap_m");
  if (!(max_gap_m > min_gap_m)) {
    Fail("ParkingParams.max_gap_m must exceed min_gap_m, got " + std::to_string(max_gap_m));
  }
  if (entry_path_points < 2) {
    Fail("ParkingParams.entry_path_points must be >= 2, got " + std::to_string(entry_path_points));
  }
  positive(associate_distance_m, "associate_distance_m");
  positive(associate_yaw_rad, "associate_yaw_rad");
  if (!(smoothing > 0 && smoothing <= 1)) {
    Fail("ParkingParams.smoothing must be in (0, 1], got " + std::to_string(smoothing));
  }
  positive(confidence_frames, "confidence_frames");
  if (!(miss_decay > 0 && miss_decay <= 1)) {
    Fail("ParkingParams.miss_decay must be in (0, 1], got " + std::to_string(miss_decay));
  }
  if (max_missed_frames < 0) {
    Fail("ParkingParams.max_missed_frames must be >= 0, got " + std::to_string(max_missed_frames));
  }
  if (min_seen_frames < 1) {
    Fail("ParkingParams.min_seen_frames must be >= 1, got " + std::to_string(min_seen_frames));
  }
}

double FootprintDistance(const GroundBox& a, const GroundBox& b) {
  const Corners ca = CornersOf(a), cb = CornersOf(b);
  if (Overlap(ca, cb)) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    for (int e = 0; e < 4; ++e) {
      best = std::min(best, PointSegment(ca[k], cb[e], cb[(e + 1) % 4]));
      best = std::min(best, PointSegment(cb[k], ca[e], ca[(e + 1) % 4]));
    }
  }
  return best;
}

void EvaluateSlot(const std::vector<GroundBox>& cars, const Pose2& ego, const ParkingParams& params,
                  ParkingSlot* slot) {
  ROMO_THROW_UNLESS(slot != nullptr);
  const Eigen::Vector2d u = slot->row_axis;
  const Eigen::Vector2d n = slot->aisle_normal;
  GroundBox ego_box;
  ego_box.length_m = params.ego_length_m;
  ego_box.width_m = params.ego_width_m;
  ego_box.yaw_rad = slot->target.yaw_rad;
  const double ego_along = HalfExtentAlong(ego_box, u) * 2;
  const double ego_across = HalfExtentAlong(ego_box, n) * 2;

  slot->approach.yaw_rad = slot->target.yaw_rad;
  const double half_diagonal = 0.5 * std::hypot(params.ego_length_m, params.ego_width_m);
  const double turn_radius = std::max(half_diagonal, ego_across / 2);
  slot->approach.position_m =
      slot->target.position_m + n * (slot->depth_m / 2 + turn_radius + params.turn_clearance_m);
  // RoMo drives straight to the spot, so it arrives with its current heading.
  slot->rotation_rad = WrapAngle(slot->target.yaw_rad - ego.yaw_rad);

  const int m = params.entry_path_points;
  slot->entry_path_m.resize(m);
  double c_prev = std::numeric_limits<double>::infinity();
  double c_next = c_prev, c_other = c_prev;
  // The turn on the spot sweeps the circle of the half diagonal around the approach spot.
  for (const auto& car : cars) {
    if (IsNeighbour(car, *slot)) continue;
    GroundBox dot;
    dot.center_m = slot->approach.position_m;
    dot.length_m = dot.width_m = 1e-6;
    c_other = std::min(c_other, FootprintDistance(dot, car) - turn_radius);
  }
  for (int k = 0; k < m; ++k) {
    const double t = static_cast<double>(k) / (m - 1);
    slot->entry_path_m[k] = (1 - t) * slot->approach.position_m + t * slot->target.position_m;
    ego_box.center_m = slot->entry_path_m[k];
    c_prev = std::min(c_prev, FootprintDistance(ego_box, slot->prev_box));
    c_next = std::min(c_next, FootprintDistance(ego_box, slot->next_box));
    for (const auto& car : cars) {
      if (!IsNeighbour(car, *slot)) c_other = std::min(c_other, FootprintDistance(ego_box, car));
    }
  }
  constexpr double kNone = 1e9;  // no such car: unbounded clearance, reported as a large number
  slot->clearance_prev_m = std::isfinite(c_prev) ? c_prev : kNone;
  slot->clearance_next_m = std::isfinite(c_next) ? c_next : kNone;
  slot->clearance_other_m = std::isfinite(c_other) ? c_other : kNone;

  std::ostringstream why;
  const double needed = ego_along + 2 * params.end_margin_m;
  if (slot->length_m < needed) {
    why << "gap " << slot->length_m << " m shorter than ego " << ego_along << " m + 2 x "
        << params.end_margin_m << " m margin";
  } else if (slot->clearance_prev_m < params.min_clearance_m ||
             slot->clearance_next_m < params.min_clearance_m) {
    why << "clearance to neighbours " << std::min(slot->clearance_prev_m, slot->clearance_next_m)
        << " m below " << params.min_clearance_m << " m";
  } else if (slot->clearance_other_m < params.min_clearance_m) {
    why << "approach or entry path blocked (clearance " << slot->clearance_other_m << " m)";
  }
  slot->reason = why.str();
  slot->feasible = slot->reason.empty();
}

std::vector<ParkingSlot> FindParkingSlots(const std::vector<GroundBox>& cars, const Pose2& ego,
                                          const ParkingParams& params) {
  params.Validate();
  for (std::size_t k = 0; k < cars.size(); ++k) CheckBox(cars[k], k);
  const int count = static_cast<int>(cars.size());

  // Cars of one heading (mod 180 deg) form a group; a group's row runs along the cars' length
  // (parallel parking) or across it (bays side by side): the layout whose neighbour gaps are
  // shorter wins, so pairs facing each other across an aisle are never taken for a bay.
  std::vector<int> group(count, -1);
  int groups = 0;
  for (int i = 0; i < count; ++i) {
    if (group[i] >= 0) continue;
    group[i] = groups;
    for (int j = i + 1; j < count; ++j) {
      if (group[j] < 0 &&
          std::abs(AxisDiff(cars[j].yaw_rad, cars[i].yaw_rad)) < params.row_yaw_tolerance_rad) {
        group[j] = groups;
      }
    }
    ++groups;
  }

  std::vector<ParkingSlot> slots;
  for (int g = 0; g < groups; ++g) {
    std::vector<int> members;
    for (int i = 0; i < count; ++i) {
      if (group[i] == g) members.push_back(i);
    }
    if (members.size() < 2) continue;
    std::array<std::vector<PairGap>, 2> gaps;
    for (int mode = 0; mode < 2; ++mode) {
      for (std::size_t x = 0; x < members.size(); ++x) {
        for (std::size_t y = x + 1; y < members.size(); ++y) {
          auto gap = GapAlong(cars, members[x], members[y], mode, params);
          if (!gap) continue;
          if (gap->end - gap->start < params.min_gap_m || gap->end - gap->start > params.max_gap_m) {
            continue;
          }
          // Only direct neighbours: no car of the row reaches into the gap.
          GroundBox gap_box;
          gap_box.yaw_rad = std::atan2(gap->u.y(), gap->u.x());
          gap_box.length_m = std::max(0.01, gap->end - gap->start - 0.1);
          gap_box.width_m = 0.5 * (HalfExtentAlong(cars[gap->i], Perp(gap->u)) +
                                   HalfExtentAlong(cars[gap->j], Perp(gap->u))) * 2;
          const double t_mid =
              0.5 * (cars[gap->i].center_m + cars[gap->j].center_m).dot(Perp(gap->u));
          gap_box.center_m = gap->u * (0.5 * (gap->start + gap->end)) + Perp(gap->u) * t_mid;
          bool occupied = false;
          for (int k = 0; k < count && !occupied; ++k) {
            if (k == gap->i || k == gap->j) continue;
            occupied = FootprintDistance(cars[k], gap_box) == 0.0;
          }
          if (!occupied) gaps[mode].push_back(*gap);
        }
      }
    }
    auto median_gap = [](const std::vector<PairGap>& v) {
      if (v.empty()) return std::numeric_limits<double>::infinity();
      std::vector<double> g;
      for (const auto& p : v) g.push_back(p.end - p.start);
      std::nth_element(g.begin(), g.begin() + g.size() / 2, g.end());
      return g[g.size() / 2];
    };
    const int mode = median_gap(gaps[0]) <= median_gap(gaps[1]) ? 0 : 1;
    for (const auto& gap : gaps[mode]) {
      const GroundBox& a = cars[gap.i];
      const GroundBox& b = cars[gap.j];
      ParkingSlot slot;
      slot.row_axis = gap.u;
      const Eigen::Vector2d n = Perp(gap.u);
      // Across the row the slot spans both neighbours from their front to their back.
      const double lo = std::min(a.center_m.dot(n) - HalfExtentAlong(a, n),
                                 b.center_m.dot(n) - HalfExtentAlong(b, n));
      const double hi = std::max(a.center_m.dot(n) + HalfExtentAlong(a, n),
                                 b.center_m.dot(n) + HalfExtentAlong(b, n));
      slot.target.position_m = gap.u * (0.5 * (gap.start + gap.end)) + n * (0.5 * (lo + hi));
      slot.length_m = gap.end - gap.start;
      slot.depth_m = hi - lo;
      // Of the two headings along the row, the one needing the smaller turn.
      const double row_yaw = std::atan2(gap.u.y(), gap.u.x());
      slot.target.yaw_rad = HeadingAlong(row_yaw, ego.yaw_rad);
      slot.aisle_normal = (ego.position_m - slot.target.position_m).dot(n) >= 0 ? n : Eigen::Vector2d(-n);
      slot.prev_id = a.id;
      slot.next_id = b.id;
      slot.prev_box = a;
      slot.next_box = b;
      EvaluateSlot(cars, ego, params, &slot);
      slots.push_back(std::move(slot));
    }
  }
  return slots;
}

ParkingSlotEstimator::ParkingSlotEstimator(const ParkingParams& params) : params_(params) {
  params_.Validate();
}

void ParkingSlotEstimator::Reset() { slots_.clear(); }

void SetDepthEdges(ParkingSlot* slot, double front_m, double rear_m) {
  ROMO_THROW_UNLESS(slot != nullptr);
  if (!(std::isfinite(front_m) && std::isfinite(rear_m) && rear_m > front_m)) {
    std::ostringstream os;
    os << "parking: slot depth edges front " << front_m << " m, rear " << rear_m
       << " m (rear must lie beyond front)";
    Fail(os.str());
  }
  slot->target.position_m -= slot->aisle_normal * (0.5 * (front_m + rear_m));
  slot->depth_m = rear_m - front_m;
}

std::vector<ParkingSlot> ParkingSlotEstimator::Update(const std::vector<GroundBox>& cars,
                                                      const Pose2& ego, const SlotRefiner& refine) {
  std::vector<ParkingSlot> found = FindParkingSlots(cars, ego, params_);
  if (refine) {
    for (ParkingSlot& cand : found) refine(cand);
  }
  std::vector<bool> matched(slots_.size(), false);
  for (auto& cand : found) {
    int best = -1;
    double best_d = params_.associate_distance_m;
    for (std::size_t t = 0; t < slots_.size(); ++t) {
      if (matched[t]) continue;
      const double d = (slots_[t].target.position_m - cand.target.position_m).norm();
      if (d < best_d && std::abs(AxisDiff(slots_[t].target.yaw_rad, cand.target.yaw_rad)) <
                            params_.associate_yaw_rad) {
        best = static_cast<int>(t);
        best_d = d;
      }
    }
    if (best < 0) {
      cand.slot_id = next_id_++;
      cand.seen_frames = 1;
      cand.missed_frames = 0;
      slots_.push_back(cand);
      matched.push_back(true);
      continue;
    }
    ParkingSlot& s = slots_[best];
    const double w = params_.smoothing;
    // Along the row the centre is smoothed; across it each edge on its own, so that an edge seen
    // on the ground is kept when only the neighbours bound it now, and taken at once when first
    // seen (it is better than any mean with the neighbours').
    const Eigen::Vector2d u0 = s.row_axis, n0 = s.aisle_normal;
    double along = s.target.position_m.dot(u0);
    double front = s.target.position_m.dot(n0) + s.depth_m / 2;  // aisle side
    double rear = s.target.position_m.dot(n0) - s.depth_m / 2;
    along += w * (cand.target.position_m.dot(u0) - along);
    const auto merge_edge = [w](double* edge, bool* from_ground, double measured, bool measured_on_ground) {
      if (measured_on_ground && !*from_ground) {
        *edge = measured;
      } else if (measured_on_ground || !*from_ground) {
        *edge += w * (measured - *edge);
      }
      *from_ground = *from_ground || measured_on_ground;
    };
    const double cand_mid = cand.target.position_m.dot(n0);
    const double cand_half = 0.5 * cand.depth_m;
    // (seen from the other side of the row, the candidate's front is the tracked slot's rear)
    const bool same_side = cand.aisle_normal.dot(n0) >= 0;
    merge_edge(&front, &s.front_from_ground, cand_mid + cand_half,
               same_side ? cand.front_from_ground : cand.rear_from_ground);
    merge_edge(&rear, &s.rear_from_ground, cand_mid - cand_half,
               same_side ? cand.rear_from_ground : cand.front_from_ground);
    s.target.position_m = u0 * along + n0 * (0.5 * (front + rear));
    s.depth_m = front - rear;
    s.target.yaw_rad =
        WrapAngle(s.target.yaw_rad + w * AxisDiff(cand.target.yaw_rad, s.target.yaw_rad));
    s.length_m += w * (cand.length_m - s.length_m);
    // Keep the row axis oriented as before so the neighbours do not swap sides.
    const bool flipped = cand.row_axis.dot(s.row_axis) < 0;
    const Eigen::Vector2d u = flipped ? Eigen::Vector2d(-cand.row_axis) : cand.row_axis;
    s.row_axis = (s.row_axis + w * (u - s.row_axis)).normalized();
    const Eigen::Vector2d n = Perp(s.row_axis);
    s.aisle_normal = n.dot(s.aisle_normal) >= 0 ? n : Eigen::Vector2d(-n);
    // The neighbours are smoothed like the gap they bound: clearances checked for a smoothed
    // target against one frame's noisy boxes came out 0.1-0.2 m short (seed 2, frames 13-15).
    const auto smooth_box = [w](const GroundBox& tracked, const GroundBox& seen) {
      const double turn = AxisDiff(seen.yaw_rad, tracked.yaw_rad);
      if (FootprintDistance(tracked, seen) > 0.0 || std::abs(turn) > kPi / 4) return seen;  // another car, or refitted
      GroundBox b = seen;
      b.center_m = tracked.center_m + w * (seen.center_m - tracked.center_m);
      b.yaw_rad = WrapAngle(tracked.yaw_rad + w * turn);
      b.length_m = tracked.length_m + w * (seen.length_m - tracked.length_m);
      b.width_m = tracked.width_m + w * (seen.width_m - tracked.width_m);
      return b;
    };
    s.prev_box = smooth_box(s.prev_box, flipped ? cand.next_box : cand.prev_box);
    s.next_box = smooth_box(s.next_box, flipped ? cand.prev_box : cand.next_box);
    s.prev_id = s.prev_box.id;
    s.next_id = s.next_box.id;
    ++s.seen_frames;
    s.missed_frames = 0;
    matched[best] = true;
  }
  for (std::size_t t = 0; t < slots_.size(); ++t) {
    if (!matched[t]) ++slots_[t].missed_frames;
  }
  slots_.erase(std::remove_if(slots_.begin(), slots_.end(),
                              [this](const ParkingSlot& s) {
                                return s.missed_frames > params_.max_missed_frames;
                              }),
               slots_.end());
  // Re-plan every slot for the ego's current pose: the aligned heading needing the smaller turn,
  // approach, path and clearances against the cars seen now and the slot's neighbours.
  for (ParkingSlot& s : slots_) {
    s.target.yaw_rad = HeadingAlong(s.target.yaw_rad, ego.yaw_rad);
    EvaluateSlot(cars, ego, params_, &s);
    if (s.feasible && s.seen_frames < params_.min_seen_frames) {
      s.reason = "measured in " + std::to_string(s.seen_frames) + " frame(s), fewer than " +
                 std::to_string(params_.min_seen_frames);
      s.feasible = false;
    }
    s.confidence = (1.0 - std::exp(-s.seen_frames / params_.confidence_frames)) *
                   std::pow(params_.miss_decay, s.missed_frames);
  }
  std::vector<ParkingSlot> out = slots_;
  std::stable_sort(out.begin(), out.end(), [](const ParkingSlot& a, const ParkingSlot& b) {
    return a.confidence > b.confidence;
  });
  return out;
}

const char* ToString(ManeuverStage stage) {
  switch (stage) {
    case ManeuverStage::kApproach: return "approach";
    case ManeuverStage::kTurn: return "turn";
    case ManeuverStage::kSideways: return "sideways";
    case ManeuverStage::kStopped: return "stopped";
    case ManeuverStage::kUnknown: break;
  }
  return "unknown";
}

ManeuverStage ManeuverStageTracker::Update(std::int64_t stamp_ns, const Pose2& pose_world) {
  if (last_stamp_ns_ && stamp_ns <= *last_stamp_ns_) return stage_;
  if (last_stamp_ns_) {
    const double dt = (stamp_ns - *last_stamp_ns_) * 1e-9;
    const Eigen::Vector2d d = pose_world.position_m - last_pose_.position_m;
    const double c = std::cos(last_pose_.yaw_rad), s = std::sin(last_pose_.yaw_rad);
    const Eigen::Vector2d v_local(( c * d.x() + s * d.y()) / dt, (-s * d.x() + c * d.y()) / dt);
    const double yaw_rate = WrapAngle(pose_world.yaw_rad - last_pose_.yaw_rad) / dt;
    ManeuverStage now;
    if (v_local.norm() < params_.min_speed_mps) {
      now = std::abs(yaw_rate) >= params_.min_yaw_rate_radps ? ManeuverStage::kTurn
                                                              : ManeuverStage::kStopped;
    } else if (std::abs(v_local.y()) > params_.sideways_ratio * std::abs(v_local.x())) {
      now = ManeuverStage::kSideways;
    } else {
      now = ManeuverStage::kApproach;
    }
    // A pause inside the maneuver belongs to the stage it interrupts.
    if (now != ManeuverStage::kStopped || stage_ == ManeuverStage::kUnknown ||
        stage_ == ManeuverStage::kStopped) {
      stage_ = now;
    }
  }
  last_stamp_ns_ = stamp_ns;
  last_pose_ = pose_world;
  return stage_;
}

}  // namespace romo::planning_iface
