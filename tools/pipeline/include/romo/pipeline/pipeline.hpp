#pragma once
/// The vehicle pipeline for one frame set, as stages: stereo (per rig) -> 360 deg fusion ->
/// ground removal -> segmentation -> boxes -> classes -> tracks -> pedestrian predictions ->
/// parking slots -> outputs. Each stage calls its module; this library only chains them, keeps
/// the state that lives across frames (tracker, slot filter, ENU origin) and times the stages.
/// Used by `romo run`, `romo replay`, `romo fuse`, `romo stereo-worker` and `romo bench pipeline`.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "romo/core/point_cloud.hpp"
#include "romo/drivers/calibration.hpp"
#include "romo/drivers/frames.hpp"
#include "romo/mapping/fusion.hpp"
#include "romo/mapping/bay_edges.hpp"
#include "romo/mapping/bay_row.hpp"
#include "romo/mapping/ground_removal.hpp"
#include "romo/mapping/segmentation.hpp"
#include "romo/objects/box.hpp"
#include "romo/objects/prediction_log.hpp"
#include "romo/objects/tracker.hpp"
#include "romo/objects/view_completion.hpp"
#include "romo/planning_iface/messages.hpp"
#include "romo/planning_iface/parking_slot.hpp"
#include "romo/stereo/sgm.hpp"

namespace romo::pipeline {

struct PipelineParams {
  int threads = 2;                ///< rigs matched in parallel (stereo), 1..64
  int disparity_size = 128;       ///< multiple of 16; 64 is enough at half resolution
  double max_range_m = 20.0;      ///< stereo points farther away are dropped
  /// Stereo points on object outlines dropped (stereo::ReprojectionParams::max_disparity_spread
  /// and min_outline_step_px). On the simulated parking scene 0.05 with no floor stops stray
  /// outline points bridging parked cars 0.9 m apart (12 of 301 car sightings merged instead of
  /// 83); a floor of 0.3 or 1 px lets the bridges back (47, 116).
  double max_disparity_spread = 0.05;
  double min_outline_step_px = 0.0;
  stereo::SgmParameters sgm = VehicleSgm();
  mapping::FusionParams fusion;
  mapping::GroundRemovalParams ground;
  mapping::SegmentationParams segmentation = DefaultSegmentation();
  /// Blobs whose box is lower than this are kerbs, lines and ground left-overs, not objects.
  double min_object_height_m = 0.5;
  /// Stereo points ignored at each end of a box's axes (depth noise at range, see FitVerticalBox).
  float box_trim_fraction = 0.03f;
  /// Blobs whose smallest rectangle is at least this long take the heading whose rectangle sides
  /// the points lie closest to (HeadingCriterion::kEdgeCloseness: a car's end face and the part
  /// of its side seen obliquely); smaller ones (people) keep the smallest rectangle. 0 = off, the
  /// default: on the simulated scene (pooled seeds 1-5, session 21, 1.5 m / off) it gives car yaw
  /// 2.5 / 7.7 deg and box centre 0.201 / 0.236 m, but cars 0.887 / 0.634 against 0.898 / 0.669
  /// and pedestrian precision 0.721 / 0.787; and a millimetre's change in the points (the int16
  /// mm of rig clouds over LCM) moves a bay's heading by up to 2 degrees where the smallest
  /// rectangle moves it by under 1. The smallest rectangle of an L whose
  /// legs are alike (a car's end and the part of its side seen at a corner) is about as small
  /// laid diagonally as along the car, so 5 m away car boxes come out 25-50 deg off; headed
  /// right, the same views (a 1.9 x 1.0 m L seen 55 deg off the car's length) no longer read as
  /// a car from the viewpoint alone, and are lost as cars or come out as people and cyclists.
  /// At full resolution (half the depth noise) ForCalibration
  /// turns it on at 1.5 m: seeds 1-5 at 782x582 with it / without, car precision 0.904 / 0.856,
  /// recall 0.651 / 0.681, pedestrians 0.836 / 0.851 and 0.738 / 0.754, box centre 0.163 /
  /// 0.202 m, car yaw 1.6 / 9.8 deg, slot found in 160 / 152 of 160 frames.
  double edge_heading_min_length_m = 0.0;
  /// A blob whose spread along the line of sight is more than this fraction depth noise (sigma_z
  /// along each point's sight line) takes its heading from its footprint's moments with the
  /// noise taken out, not from the smallest rectangle around the smeared points.
  double noise_dominated_fraction = 0.5;
  /// Blobs of no class closer than this (footprints' gap, m) whose union is one of
  /// fragment_merge_classes are merged: far car fronts split by depth noise and stereo gaps into
  /// pieces too narrow for anything. Pedestrians are not formed this way (merging would hide a
  /// person beside a car's front); 0 turns merging off.
  double fragment_merge_gap_m = 1.0;
  std::vector<std::string> fragment_merge_classes = {"car"};
  /// Blobs of no class one above the other (footprint centres closer than stacked_merge_xy_m,
  /// less than stacked_merge_gap_m between them) whose union is one of stacked_merge_classes, no
  /// more than a sigma short of its mean height, are merged: a person 10-15 m away often breaks at
  /// the waist, where stereo finds no texture, into legs and a floating torso too short for
  /// anyone. 0 turns it off.
  double stacked_merge_xy_m = 0.5;
  double stacked_merge_gap_m = 0.5;
  std::vector<std::string> stacked_merge_classes = {"pedestrian"};
  /// A pedestrian-tall blob at least this long (less depth noise) is split in two along its
  /// length when both halves are pedestrians: two people walking one behind the other along the
  /// sight line stay one blob (0.6 m apart on the simulated scene: 56 of 196 pedestrian sightings
  /// lost). 0.9 m is longer than one person's stride (Atlas pedestrian mean + 1.2 sigma). 0 = off.
  double tandem_min_length_m = 0.9;
  /// ... or when the nearer half is a pedestrian and the farther half, hidden behind it in part
  /// (a sliver beside it, or legs below it), can be one partly seen (PartlySeenPerson): the far
  /// one is then a pedestrian too, its box from the ground up. false = both must read as people.
  bool tandem_far_partly_seen = true;
  /// ... and one read as no person, as long as two people side by side (up to twice the Atlas
  /// pedestrian length max, no deeper than that max) and standing at least aisle_pair_min_gap_m in
  /// front of the row's front line (bays_from_paint), is split in two along its length when both
  /// halves are people, however it is seen: no parked car's end stands in the aisle (the
  /// simulated scene's pair walking side by side 1.3 m apart, read as a car's end or a cyclist
  /// 5-10 m away). 0 = off.
  double aisle_pair_min_gap_m = 1.0;
  /// A blob at least this long seen across its length (the sight line nearer its width than its
  /// length) is split at the emptiest stretch inside it (or the next emptiest, and so on) holding
  /// less than face_pair_gap_density of the blob's median points per length where both parts are cars: the
  /// ends of two cars parked side by side, 0.6 to 1 m apart, bridged by stereo edge fattening, read
  /// as one car seen side-on and boxed across both (its centre a metre off each). 3.0 m is longer
  /// than any car end (Atlas width max 2.6 m); 0 turns the split off. The gap of two car ends
  /// 13 m away keeps 0.4 of the median (the near car's corner fills it): 0.5 splits those too
  /// (seeds 6-10: car recall 0.596 -> 0.618, pedestrian precision 0.671 -> 0.689; seeds 1-5 alike).
  double face_pair_min_length_m = 3.0;
  double face_pair_gap_density = 0.5;
  /// A car-classed blob at least framed_min_length_m long whose two ends, seen from its camera,
  /// both meet objects nearer by framed_occluder_margin_m is left unclassified: its length is only
  /// where the nearer objects cut it off (a hedge or wall seen through the gap between two parked
  /// cars), so it says nothing about a car. 2.6 m is longer than any car front (Atlas width max),
  /// so a car front between two cars stays a car; 0 turns the check off.
  double framed_min_length_m = 2.6;
  double framed_occluder_margin_m = 0.8;
  /// How far beyond an end (degrees, seen from the camera) a nearer object still frames it.
  double framed_end_gap_deg = 6.0;
  /// Cars parked side by side stand across the line through their seen ends: a car at least
  /// row_align_min_range_m away whose heading is more than row_align_min_off_deg off that of the
  /// row it stands in is refitted and completed along the row's. Far off, stereo smears a car's
  /// end seen obliquely along the sight line, and its box follows the sight line instead of the
  /// car (40-50 deg off, its centre 1.5-2 m away on the simulated scene). A row is at least
  /// row_align_min_cars cars (this one among them) whose measured centres lie within
  /// row_align_max_offset_m of one line and within row_align_radius_m of this car, neighbours
  /// closer along it than a car is long (Atlas length mean less a sigma), and at least
  /// row_align_min_agreeing of the others boxed along the row's heading already. A refit whose
  /// completed footprint, less row_align_free_ground_margin_m all round, holds
  /// row_align_free_ground_points ground points is no car there and is not taken (a car's side
  /// seen through a gap reads as its end, and is completed out over the ground behind). 0 cars = off.
  int row_align_min_cars = 3;
  double row_align_radius_m = 12.0;
  double row_align_max_offset_m = 0.3;
  double row_align_min_range_m = 8.0;
  double row_align_min_off_deg = 20.0;
  int row_align_min_agreeing = 1;
  double row_align_free_ground_margin_m = 0.1;
  int row_align_free_ground_points = 10;
  /// A box whose bottom is higher than this above the ground plane is not a car or pedestrian.
  double max_ground_gap_m = 0.4;
  /// A box whose bottom is at most this above the ground plane stands on it and reaches down to
  /// it (objects::StandOnGround) before it is classified: ground removal (0.1 m) takes a car's or
  /// person's lowest points with the ground, and their boxes came out 0.15-0.2 m short (simulated
  /// scene: matched boxes' bottoms at 0.14 m median, 95 % under 0.2, 99 % under 0.3), so a person
  /// 1.7 m tall read as 1.5. Pooled seeds 1-10 with the Atlas's person and cyclist heights bounded
  /// from 1.5 m (config/atlas.yaml): pedestrians P / R 0.881 / 0.776 -> 0.882 / 0.803, cars 0.935
  /// / 0.822 -> 0.928 / 0.823. 0 = boxes as measured.
  double ground_contact_gap_m = 0.25;
  /// Parked cars are remembered in the world frame while the ground under them stays unseen: a
  /// car hidden behind the row in front, or cut off by the field of view, is still there. A car
  /// track seen as a car and slower than parked_max_speed_mps is remembered; it is forgotten once
  /// parked_free_ground_points ground points show inside its footprint (less
  /// parked_footprint_margin_m all round), or beyond parked_max_range_m. 0 points turns memory off.
  int parked_free_ground_points = 20;
  double parked_max_speed_mps = 0.5;
  /// The speed gate grows by this (1/s) times the blob's depth spread: a far parked car's box
  /// jumps with stereo's depth noise and its track's filtered speed with it (0.8-2.5 m/s 10 m
  /// away on the simulated scene). A view passing only the grown gate starts a memory but never
  /// replaces one remembered from a view under parked_max_speed_mps (a steadier box). Pooled seeds
  /// 1-5: cars 0.898 / 0.669 -> 0.925 / 0.733; seeds 6-10: 0.879 / 0.682 -> 0.883 / 0.692;
  /// pedestrians and slots alike. 0 = the fixed gate.
  double parked_speed_per_depth_spread = 0.25;
  double parked_footprint_margin_m = 0.3;
  double parked_max_range_m = 25.0;
  /// ... unless the objects seen now hold at least this many points per such ground point inside
  /// its footprint (grown by the margin): a neighbour beside the vehicle during the sideways entry
  /// shows its side wall (tens of thousands of points) while stereo puts a hundred mismatches of
  /// its low side at ground height behind the wall. A car driven off leaves ground and no wall; a
  /// person crossing the freed bay holds fewer points than the bay's ground. Simulated scene:
  /// neighbour sightings within 6 m missed in the turn and entry (frames 30-39, seeds 1-10) 29 ->
  /// 7, false cars there 28 -> 10; seeds 1-5 car precision 0.878 -> 0.894, recall 0.630 -> 0.635
  /// (seeds 6-10: 0.868 -> 0.878, 0.650 -> 0.649). 0 turns the exception off.
  double parked_standing_points_ratio = 50.0;
  /// A remembered car is the latest view of it that showed at least parked_keep_view_fraction of
  /// the most any view showed (points x squared range: the surface seen), not simply the latest:
  /// the last views before a car goes behind the one in front, or out of the field of view, are
  /// slivers, completed wrong. Simulated scene, pooled: seeds 1-5 cars 0.896 / 0.660 -> 0.898 /
  /// 0.669 (precision / recall), seeds 6-10 0.877 / 0.672 -> 0.879 / 0.682, pedestrians and slots
  /// alike; the median centre error 0.233 -> 0.236 m and 0.244 -> 0.255 m, the memory now finding
  /// more hidden cars (68 -> 73 and 77 -> 85), boxed less closely than cars in view. (A car that
  /// moves off is forgotten by the ground seen where it stood.) 0 = always the latest view.
  double parked_keep_view_fraction = 0.8;
  /// A car seen now with at least this fraction of its points inside a remembered parked car's
  /// footprint (grown by parked_footprint_margin_m) takes that footprint when its own completed
  /// box's centre is more than parked_prefer_offset_m away: the neighbours beside the vehicle
  /// during the sideways entry are cut by the field of view to a stretch of their side, boxed
  /// along the row, while the car was seen whole from the aisle. Two cars seen inside one
  /// remembered footprint keep their own boxes: that memory is wrong (a box laid across two
  /// neighbours' ends). 1 < fraction turns this off.
  double parked_prefer_fraction = 0.9;
  double parked_prefer_offset_m = 0.5;
  /// ... only when the car's nearest point is at most this far from the vehicle. Farther out the
  /// memory was formed from as far away and is no better than the view now; and one formed wrong
  /// (10-15 m away stereo bridges the ends of two neighbours, boxed between them) took every later
  /// view of either car for itself, and kept both missed while the vehicle drove up the row.
  /// Simulated scene, seeds 1-5 pooled: car precision 0.890 -> 0.896, recall 0.635 -> 0.660, pedestrian
  /// precision 0.762 -> 0.786, recall 0.719 -> 0.726 (seeds 6-10: cars 0.877 / 0.649 -> 0.877 /
  /// 0.672, pedestrians 0.774 / 0.721 -> 0.762 / 0.726); 4-5.5 m score alike, 6 m loses recall.
  /// At full resolution ForCalibration turns the limit off: seeds 1-5 at 782x582 without / with
  /// it, cars 0.900 / 0.648 and 0.882 / 0.649, pedestrians 0.828 / 0.738 and 0.862 / 0.733; seed
  /// 1's car precision 0.971 / 0.859 (a far car remembered well, missed from its later views).
  double parked_prefer_max_range_m = 5.0;
  /// A pedestrian detection inside a remembered parked car is a piece of its end (stereo breaks a
  /// car end 10-15 m away into bumper, lamps and window, each a person's size): it is left of no
  /// class. On the simulated scene (seeds 1-5) 56 false pedestrian sightings lay so inside cars
  /// hidden now, and one real one. It holds as well while a car detection stands in the memory:
  /// the pieces a car box leaves out beside it are no people either (pedestrian precision, pooled,
  /// seeds 1-5 0.791 -> 0.795, seeds 6-10 0.762 -> 0.765, recall the same).
  bool parked_pieces_unclassified = true;
  /// The same within parked_pieces_margin_m around the remembered footprint: a remembered car is
  /// boxed a little short or aside, and its end's pieces stick out (seeds 1-5: of the pedestrian
  /// sightings within 0.6 m outside a hidden remembered car, 63 false and none real). A person
  /// whose track walked parked_pieces_walked_m from where it began, to within a stride of the
  /// sighting, came up to the car and stays a person there (inside the footprint too few real
  /// people stood to tell). Pooled pedestrians with the margin, seeds 1-5: P / R 0.795 / 0.751 ->
  /// 0.881 / 0.745, seeds 6-10: 0.754 / 0.767 -> 0.815 / 0.761. 0 = the footprint alone.
  double parked_pieces_margin_m = 0.5;
  double parked_pieces_walked_m = 2.0;
  /// A pedestrian track (its class voted over its views) whose blob now is too low for a person
  /// (legs hidden behind a car's bonnet or a low wall, or lost by stereo 10-15 m away: a torso
  /// floating above the ground) stays a pedestrian when the blob's footprint can be a person's and
  /// its top is no higher than one is tall; its box then reaches down to the ground. Planning
  /// must not lose a person to a partial view. Pooled pedestrians, seeds 1-5: P / R 0.795 / 0.726
  /// -> 0.795 / 0.751; seeds 6-10: 0.765 / 0.726 -> 0.754 / 0.767 (a few tracks that had moved
  /// onto a car's piece keep calling it a person).
  bool pedestrian_tracks_keep_partial_views = true;
  /// Corner views read either side as cut off (corner_angle_deg 50): in a row of parked cars the
  /// neighbour or the field of view often cuts one (simulated scene, seeds 1-5, measured with edge
  /// closeness headings on: car recall 0.520
  /// without, 0.564 with, precision 0.798 and 0.791).
  objects::ViewCompletionParams completion = CarParkCompletion();
  objects::TrackerParams tracker;
  objects::PredictorKind predictor = objects::PredictorKind::kRls;
  planning_iface::ParkingParams parking;
  /// A bay's depth is read off the ground through the gap (painted front line, kerb:
  /// mapping::FindBayEdges) on a strip bay_strip_margin_m narrower than the gap at either end
  /// (the separator lines and the neighbours' sides stay out); false: the neighbours bound it.
  bool bay_edges_from_ground = true;
  mapping::BayEdgeParams bay_edges;
  double bay_strip_margin_m = 0.3;
  /// Parked cars placed by the paint of the row they stand in (mapping::FindBayRow): 10-15 m
  /// off a car is seen as an end smeared along the sight line, its box follows the sight line
  /// (40-60 deg off) and lands between two bays, and its neighbours' ends are pieces too small
  /// for a car. false: boxes as seen. Pooled over seeds 1-10 (simulated scene), cars P / R
  /// 0.906 / 0.717 -> 0.881 / 0.814, pedestrians 0.845 / 0.754 -> 0.856 / 0.764 (with the
  /// memory fixes of the same session: GroundRemovalParams::below_tolerance_m, RememberParkedCars).
  bool bays_from_paint = true;
  mapping::BayRowParams bay_row;
  /// A box's or piece's front part: its points up to bay_front_m behind the front line. Its face:
  /// its points up to bay_face_depth_m behind its front (10th percentile depth).
  double bay_front_m = 1.2;
  double bay_face_depth_m = 0.5;
  /// A car box whose front part lies mostly in one bay between two separators
  /// bay_snap_min_width_m to bay_snap_max_width_m apart (a wider one is a free bay), while its
  /// centre is more than bay_snap_min_offset_m off the bay's centre line or its heading more than
  /// bay_snap_min_off_deg off the bay's, is moved onto that line along the bay. One off the
  /// heading where no bay is seen is turned to it and centred on its face, when the face spans
  /// no more than bay_snap_max_face_m (more: several cars' faces). Its front stays where its points'
  /// is. Not where more than row_align_free_ground_points ground points, and
  /// bay_snap_ground_ratio times those in the box as seen, show inside.
  double bay_snap_min_width_m = 2.0;
  double bay_snap_max_width_m = 3.3;
  double bay_snap_min_offset_m = 0.5;
  double bay_snap_min_off_deg = 20.0;
  double bay_snap_max_face_m = 3.0;
  double bay_snap_ground_ratio = 1.2;
  /// A piece of no class (or read as a person or a cyclist where no walker stood:
  /// parked_pieces_walked_m; a car's end seen edge-on is a bicycle's length and width) whose front lies from bay_face_front_tolerance_m before the front line to bay_front_m behind
  /// it, whose face spans bay_face_min_spread_m (wider than a person) to the Atlas car width max
  /// plus bay_face_width_slack_m, at least bay_face_min_range_m away, clear of the cars, and
  /// showing ground inside no more than bay_face_max_ground_ratio times its points, is a car seen
  /// end-on between its neighbours: boxed along the bays from its face with the Atlas car's mean
  /// size and score bay_face_score.
  /// ... and a piece there of no class (or read as a car seen side-on lying along the front line,
  /// across which parked cars stand) whose face is wider than that, and at most twice, is the ends
  /// of two neighbours seen along the row, joined by stereo's smear along the sight line: it is
  /// split at the sparsest stretch along the row (face_pair_gap_density) that leaves each part at
  /// least bay_face_min_spread_m and no wider than a car's end, before the parts are completed
  /// (the simulated scene's cars 106 and 107, seed 2, frames 8-12: one piece 3.6-4.4 m across).
  /// false = such pieces stay whole.
  bool split_row_faces = true;
  double bay_face_front_tolerance_m = 0.3;
  double bay_face_min_spread_m = 0.6;
  double bay_face_width_slack_m = 0.3;
  double bay_face_min_range_m = 6.0;
  double bay_face_max_ground_ratio = 0.2;
  double bay_face_score = 0.5;
  std::string atlas_path;  ///< "" = objects::Atlas::DefaultPath()

  static mapping::SegmentationParams DefaultSegmentation();
  static objects::ViewCompletionParams CarParkCompletion();
  static stereo::SgmParameters VehicleSgm();
  /// Defaults for @p calibration's image size (half-resolution images need half the disparity
  /// range for the same nearest depth; full-resolution ones take L-shape headings for long
  /// blobs and prefer remembered parked cars at any range) with @p threads stereo threads.
  static PipelineParams ForCalibration(const drivers::Calibration& calibration, int threads);
  /// The same for rigs whose images are @p image_width_px wide (what a stereo worker says of
  /// the clouds it sends). @throws romo::Error for a width < 1.
  static PipelineParams ForImageWidth(int image_width_px, int threads);
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// Wall time of one stage of one frame.
using planning_iface::StageLatency;

/// One rig's cloud entering fusion (from the in-process stereo stage or a stereo worker).
struct RigInput {
  int rig_id = 0;
  std::int64_t stamp_ns = 0;
  PointCloud cloud;  ///< vehicle frame (romo::stereo reprojects through T_vehicle_rig)
  double stereo_ms = 0.0;
};

/// Everything one frame produced.
struct FrameResult {
  std::int64_t stamp_ns = 0;
  std::int64_t frame_sequence = 0;
  Eigen::Isometry3d T_world_vehicle = Eigen::Isometry3d::Identity();
  planning_iface::Pose2 ego_world;
  PointCloud cloud;                ///< fused, vehicle frame
  mapping::Plane ground_plane;
  bool ground_refined = false;
  std::vector<int> ground_indices;
  std::vector<std::vector<int>> blobs;          ///< into cloud
  std::vector<objects::Box3> boxes;             ///< vehicle frame, one per kept blob
  std::vector<std::string> box_classes;
  std::vector<objects::Track> tracks;           ///< world frame
  std::vector<objects::PedestrianPrediction> predictions;
  planning_iface::ObstacleList obstacles;       ///< vehicle frame
  planning_iface::ParkingSlotReport slots;      ///< world frame (+ ego pose)
  planning_iface::PerceptionStatus status;
  std::vector<int> missing_rigs;
};

class Pipeline {
 public:
  /// @throws romo::Error for invalid params, a calibration without rigs or an unreadable Atlas.
  Pipeline(const drivers::Calibration& calibration, const PipelineParams& params);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Stereo for every rig of @p frames, then ProcessClouds.
  /// @throws romo::Error when a stereo frame does not match its calibration.
  FrameResult Process(const drivers::FrameSet& frames);

  /// Stereo only: the rig's cloud (what a stereo worker publishes); nullopt when the rig's
  /// images could not be matched (counted as dropped, reported as an event).
  std::optional<RigInput> Stereo(const drivers::StereoFrame& frame);

  /// Everything after stereo. Rigs of the calibration absent from @p rigs are reported missing
  /// (status event, rig not present) and the frame is processed without them.
  /// @throws romo::Error when stamps go backwards (out-of-order input).
  FrameResult ProcessClouds(std::int64_t stamp_ns, std::int64_t frame_sequence,
                            const std::vector<RigInput>& rigs,
                            const std::optional<drivers::VehicleState>& vehicle,
                            const std::optional<drivers::GnssFix>& gnss);

  /// Counts a frame dropped upstream (reported in the status).
  void CountDropped(int rig_id);
  /// Counts a malformed network message (reported in the status).
  void CountMalformed();
  /// Adds a line to the next status' events.
  void ReportEvent(const std::string& event);
  /// The last frame's status carrying the events reported since it, for faults found when no
  /// frame follows (a recording truncated after its last complete frame); nullopt if none pending.
  std::optional<planning_iface::PerceptionStatus> TakePendingStatus();

  const drivers::Calibration& calibration() const;
  const PipelineParams& params() const;
  const objects::Atlas& atlas() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace romo::pipeline
