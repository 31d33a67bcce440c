#pragma once
/// Parking-slot estimation from the boxes of parked cars (dissertation 4.3.3, ref. [99]).
/// Pure 2D geometry in the ground plane of one frame (vehicle or world: the caller names it);
/// no middleware. The maneuver it plans is RoMo's: drive forward to an approach spot centred in
/// front of the gap, rotate on the spot until aligned with the row of neighbours (the ego's
/// length along the row), drive sideways (crab) into the gap. The row runs along the cars for
/// parallel parking and across them for bays side by side; either way the ego's length lies
/// along the row, so a gap fits when it is longer than the ego plus both end margins.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace romo::planning_iface {

/// A yaw-only box footprint on the ground (the top view of a vertical cuboid).
struct GroundBox {
  Eigen::Vector2d center_m = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;   ///< direction of the length axis
  double length_m = 0.0;  ///< extent along yaw
  double width_m = 0.0;   ///< extent across yaw
  int id = -1;            ///< track id or index; reported as a slot's neighbour
};

/// A planar pose (position and heading) in the same frame as the boxes.
struct Pose2 {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
};

struct ParkingParams {
  double ego_length_m = 2.8;  ///< RoMo
  double ego_width_m = 1.6;
  /// Free space required between the ego and each neighbour once parked, along the row.
  double end_margin_m = 0.2;
  /// The ego footprint never comes closer than this to any car along the whole entry path.
  double min_clearance_m = 0.15;
  /// Turning on the spot sweeps a circle of the ego's half diagonal: the approach spot keeps
  /// this much more from the row's front edge and from every car.
  double turn_clearance_m = 0.3;
  /// Two cars belong to one row when their headings differ by less than this (mod 180 deg)...
  double row_yaw_tolerance_rad = 0.35;
  /// ...and their centres are this close to one line along the row.
  double row_lateral_tolerance_m = 1.0;
  /// Gaps shorter than this are touching cars, longer ones are open road, not bays.
  double min_gap_m = 0.5;
  double max_gap_m = 10.0;
  int entry_path_points = 11;  ///< samples from approach spot to slot centre, both included

  // Filtering over frames (ParkingSlotEstimator).
  double associate_distance_m = 1.0;   ///< a candidate joins a tracked slot this close
  double associate_yaw_rad = 0.26;
  double smoothing = 0.4;              ///< weight of the new measurement in the running mean
  double confidence_frames = 3.0;      ///< confidence = 1 - exp(-hits / this) ...
  double miss_decay = 0.7;             ///< ... times this per consecutive frame not seen
  int max_missed_frames = 15;          ///< then the slot is forgotten
  /// A slot is feasible only once measured in this many frames: one frame's gap may be a
  /// neighbour stereo missed (simulated scene seed 1 at full resolution: a car beside the
  /// narrow bay missed from frame 12 on left a 4.2 m gap, seen once, then kept 15 frames as
  /// feasible since no car seen later stood in it).
  int min_seen_frames = 2;

  /// @throws romo::Error naming the field and value when a value is out of range.
  void Validate() const;
};

/// One free gap between two neighbouring parked cars and the maneuver into it.
struct ParkingSlot {
  int slot_id = -1;  ///< stable over frames (ParkingSlotEstimator); -1 from FindParkingSlots
  Pose2 target;      ///< where the ego ends: centred in the gap, heading along the row
  double length_m = 0.0;  ///< free length along the row between the neighbours
  double depth_m = 0.0;   ///< extent across the row (front to back of both neighbours)
  /// Whether the bay's front (aisle side) and rear edges were measured on the ground (painted
  /// line, kerb: a SlotRefiner) rather than taken from the neighbours' boxes; once measured, an
  /// edge is no longer moved by the neighbours.
  bool front_from_ground = false;
  bool rear_from_ground = false;
  Eigen::Vector2d row_axis = Eigen::Vector2d::UnitX();  ///< unit, from prev to next neighbour
  Eigen::Vector2d aisle_normal = Eigen::Vector2d::UnitY();  ///< unit, from the row to the aisle
  int prev_id = -1;
  int next_id = -1;
  GroundBox prev_box;  ///< the neighbours as last seen (before / after the gap along row_axis)
  GroundBox next_box;
  Pose2 approach;            ///< spot in front of the gap, heading already aligned (after the turn)
  double rotation_rad = 0.0;  ///< turn on the spot: aligned heading minus arrival heading
  std::vector<Eigen::Vector2d> entry_path_m;  ///< approach spot -> target, sideways
  double clearance_prev_m = 0.0;  ///< least ego-to-neighbour distance along the entry path
  double clearance_next_m = 0.0;
  double clearance_other_m = 0.0;  ///< least distance to any other car (turn circle and path)
  bool feasible = false;
  std::string reason;        ///< why not feasible ("" when feasible)
  double confidence = 0.0;   ///< 0..1, from ParkingSlotEstimator
  int seen_frames = 0;
  int missed_frames = 0;
};

/// Distance between two box footprints in metres; 0 when they touch or overlap.
double FootprintDistance(const GroundBox& a, const GroundBox& b);

/// Fills approach, rotation, entry path, clearances and feasibility of @p slot (whose target,
/// length, depth, axes and neighbour boxes are set) against its neighbours and every other car
/// of @p cars (boxes overlapping a neighbour count as that neighbour) for the ego at @p ego.
void EvaluateSlot(const std::vector<GroundBox>& cars, const Pose2& ego, const ParkingParams& params,
                  ParkingSlot* slot);

/// Every gap between neighbouring cars of a row, evaluated for the ego at @p ego.
/// @throws romo::Error when @p params is invalid or a box has a non-finite or non-positive size.
std::vector<ParkingSlot> FindParkingSlots(const std::vector<GroundBox>& cars, const Pose2& ego,
                                          const ParkingParams& params);

/// Moves the aisle-side (front) and far (rear) edges of @p slot to @p front_m and @p rear_m,
/// measured from its target into the bay (against aisle_normal); target and depth follow.
void SetDepthEdges(ParkingSlot* slot, double front_m, double rear_m);

/// Measures a candidate slot's depth edges on something other than its neighbours (SetDepthEdges
/// and the *_from_ground flags), before it is merged into the tracked slots.
using SlotRefiner = std::function<void(ParkingSlot& candidate)>;

/// Keeps slots stable over frames: slots live in a fixed frame (world when the vehicle pose is
/// known), are associated by position, smoothed, given a confidence, and re-planned (approach,
/// rotation, path, clearance) for the ego's current pose every frame.
class ParkingSlotEstimator {
 public:
  explicit ParkingSlotEstimator(const ParkingParams& params = {});
  /// @param cars parked-car boxes in the fixed frame; @param ego the ego pose in that frame.
  /// @return every tracked slot (seen now or recently), best confidence first.
  /// @param refine when set, applied to every slot found among @p cars before merging.
  std::vector<ParkingSlot> Update(const std::vector<GroundBox>& cars, const Pose2& ego,
                                  const SlotRefiner& refine = {});
  const std::vector<ParkingSlot>& slots() const { return slots_; }
  void Reset();

 private:
  ParkingParams params_;
  std::vector<ParkingSlot> slots_;
  int next_id_ = 0;
};

/// The stage of RoMo's parking maneuver, inferred from the vehicle's motion.
enum class ManeuverStage : std::uint8_t { kUnknown = 0, kApproach = 1, kTurn = 2, kSideways = 3, kStopped = 4 };
const char* ToString(ManeuverStage stage);

/// Infers the stage from consecutive vehicle poses: forward motion = approach, rotation with
/// little translation = turn, motion mostly along the vehicle's y axis = sideways entry.
class ManeuverStageTracker {
 public:
  struct Params {
    double min_speed_mps = 0.05;     ///< slower than this and not turning: stopped
    double min_yaw_rate_radps = 0.05;
    double sideways_ratio = 1.0;     ///< |v_y| > ratio * |v_x| is sideways
  };
  ManeuverStageTracker() : ManeuverStageTracker(Params{}) {}
  explicit ManeuverStageTracker(const Params& params) : params_(params) {}
  /// @param stamp_ns must increase; a repeated or older stamp keeps the last stage.
  ManeuverStage Update(std::int64_t stamp_ns, const Pose2& pose_world);
  ManeuverStage stage() const { return stage_; }

 private:
  Params params_;
  std::optional<std::int64_t> last_stamp_ns_;
  Pose2 last_pose_;
  ManeuverStage stage_ = ManeuverStage::kUnknown;
};

/// Angle wrapped into (-pi, pi].
double WrapAngle(double rad);

}  // namespace romo::planning_iface
