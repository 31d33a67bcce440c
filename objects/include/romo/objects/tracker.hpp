#pragma once
/// Multi-object tracking in the ground plane (dissertation 4.3.4, Fig. 4.16): a constant-velocity
/// Kalman filter per track, Mahalanobis gating, optimal (Hungarian) assignment, a
/// tentative/confirmed/lost lifecycle, coasting through total occlusion, and merged blobs of two
/// pedestrians shared by both of their tracks (partial occlusion). Pedestrian tracks carry an
/// RLS path prediction.
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "romo/objects/atlas.hpp"
#include "romo/objects/box.hpp"
#include "romo/objects/path_prediction.hpp"

namespace romo::objects {

/// One blob's box in the tracking frame (ground plane xy, z up), with its Atlas class.
struct Detection {
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();  ///< footprint centre
  double yaw_rad = 0.0;                            ///< footprint heading (mod pi)
  double length_m = 0.0;                           ///< footprint, length >= width
  double width_m = 0.0;
  double height_m = 0.0;
  Classification classification;

  /// From a vertical box (centre xy, size, yaw) classified by @p atlas.
  static Detection FromBox(const Box3& box, const Atlas& atlas);
  /// From a vertical box already classified (e.g. by ClassifyFromViewpoint).
  static Detection FromBox(const Box3& box, const Classification& classification);
};

enum class TrackState {
  kTentative,  ///< seen fewer than confirm_hits times
  kConfirmed,  ///< seen in the last frame
  kLost,       ///< confirmed, not seen now: coasting on its prediction (total occlusion)
};
const char* ToString(TrackState state);

/// A track as reported after each Update().
struct Track {
  int id = 0;
  TrackState state = TrackState::kTentative;
  int class_index = -1;           ///< Atlas class voted by its detections
  double class_score = 0.0;       ///< mean score of the winning class's votes
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();   ///< filtered (or coasted) position
  Eigen::Vector2d velocity_mps = Eigen::Vector2d::Zero();
  Eigen::Matrix2d position_cov_m2 = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d velocity_cov_m2ps2 = Eigen::Matrix2d::Zero();  ///< (m/s)^2
  double yaw_rad = 0.0;           ///< box heading, unwrapped against the track (mod pi)
  double length_m = 0.0, width_m = 0.0, height_m = 0.0;
  double first_seen_s = 0.0;
  double last_seen_s = 0.0;       ///< time of the last associated detection
  int hits = 0;                   ///< associated detections so far
  bool merged = false;            ///< shares a merged blob with another track this frame
  int companion_id = -1;          ///< lost: the track it follows (TrackerParams::companion_*), or -1
  int detection_index = -1;       ///< detection associated this frame, or -1
  /// Last observed position (the RLS trail's newest point) and its time.
  Eigen::Vector2d observed_xy_m = Eigen::Vector2d::Zero();
  double observed_s = 0.0;
  /// Predicted path from the last observation (pedestrian classes; kept through occlusion).
  std::vector<PredictedPoint> predicted_path;
};

struct TrackerParams {
  double measurement_sigma_m = 0.15;   ///< position noise of a single-object detection
  double accel_sigma_mps2 = 1.5;       ///< white-noise acceleration of the CV model
  double initial_speed_sigma_mps = 2.0;
  /// Mahalanobis gate (chi-square, 2 dof): 13.8 = 99.9 %; occluded tracks' grown covariance
  /// widens their gate by itself.
  double gate_chi2 = 13.8;
  int confirm_hits = 3;
  /// A tentative track dies after this many frames without a detection.
  int tentative_max_misses = 1;
  /// Total occlusion: a confirmed track coasts this long without detections (s); a class's
  /// Atlas max_occlusion_s overrides it when larger.
  double max_occlusion_s = 2.0;
  /// Partial occlusion: a blob that is pedestrian-tall but longer than a typical pedestrian
  /// (Atlas mean + sigma) may be shared by up to this many pedestrian tracks.
  int max_tracks_per_blob = 2;
  /// Tracks sharing a blob are held inside it, side by side along its long axis in the order
  /// of their predictions: each centre lies this far inside the blob's end (half a body).
  double merged_inset_m = 0.25;
  double merged_sigma_m = 0.3;         ///< noise of that in-blob position
  /// People walking together (side by side, or one behind the other along the sight line) hide
  /// each other: a pedestrian track lost while another pedestrian track within
  /// companion_max_gap_m is measured walking (at least companion_min_speed_mps) at nearly its
  /// velocity (within companion_max_speed_diff_mps) follows that companion at the offset it had
  /// when lost, for up to companion_max_occlusion_s, instead of coasting on its own velocity.
  /// 0 gap = off. While the companion stands still the follower waits with it (people walking
  /// together stop together) when it was lost at least companion_standing_min_gap_m from it;
  /// nearer, the two are as likely one person tracked twice (two tracks sharing one blob), and it
  /// coasts alone. A follower nearer than that to another person measured now is that person,
  /// tracked twice, and ends. While the companion is hidden too, the follower walks on beside its coasting
  /// track and is placed beside it again once it is seen; should the companion's track end, the
  /// follower coasts alone, its occlusion limit counted from where a measured companion last
  /// placed it. With the tandem split's partly seen far walker, simulated scene at full
  /// resolution, seeds 1-5: pedestrians 0.942 / 0.859 -> 0.953 / 0.895 (the far one of a pair in
  /// single file, hidden while both stand at the turning spot). The gap is between the two tracks'
  /// estimates, which carry the lost one's error: 2 m for people 1.3 m apart (seed 1's follower was
  /// 1.69 m from its walker when lost, and coasted through it when it stopped; 1.6 m before
  /// session 35).
  double companion_max_gap_m = 2.0;
  double companion_min_speed_mps = 0.4;
  double companion_max_speed_diff_mps = 0.5;
  double companion_max_occlusion_s = 8.0;
  double companion_standing_min_gap_m = 0.8;
  /// A follower glimpsed (a detection that is no whole person: of another class, or thinner than
  /// a person's footprint, Atlas width mean - sigma: a sliver beside the one in front, legs below
  /// a bonnet) keeps following: the glimpse moves it as a position anywhere within a person's
  /// largest footprint (Atlas length max), and it keeps its companion's velocity. A glimpse's
  /// centre is off by which part shows (0.3-1.0 m for slivers bridged by stereo to the one in
  /// front), so a full update took a velocity error of a metre a second from it and broke the
  /// pair. A glimpse farther than companion_max_gap_m from the companion is someone else's.
  bool companion_glimpses = true;
  /// A detection read as a pedestrian that a pedestrian track (past tentative) gates is not taken
  /// by a track of another class moving faster than the Atlas pedestrian's max_speed_mps: no
  /// person's, such a track (a piece of a parked car coasting on 3 m/s taken from stereo noise)
  /// took a walker's detection as the walker turned and left the walker's track a sliver beside
  /// it (simulated scene, full resolution, seed 5 frame 16). Slower tracks of another class may
  /// be a person not yet voted one (half resolution, seed 10).
  bool people_for_pedestrian_tracks = true;
  PredictorParams predictor;           ///< path prediction for predict_path classes
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

class Tracker {
 public:
  /// @throws romo::Error when @p params are invalid or the atlas lacks a "pedestrian" class.
  Tracker(const Atlas& atlas, const TrackerParams& params);
  ~Tracker();
  Tracker(Tracker&&) noexcept;
  Tracker& operator=(Tracker&&) noexcept;

  /// Advances every track to @p stamp_s (strictly increasing), associates @p detections and
  /// updates the lifecycle. Returns the live tracks (tentative, confirmed, lost).
  /// @throws romo::Error when the stamp does not increase or a detection is not finite.
  const std::vector<Track>& Update(double stamp_s, const std::vector<Detection>& detections);
  const std::vector<Track>& tracks() const;

  /// The yaw of the live track whose predicted position gates @p xy_m best, to pass to
  /// FitVerticalBox as a heading hint; nullopt when none gates it.
  std::optional<double> YawHint(const Eigen::Vector2d& xy_m) const;

  const Atlas& atlas() const;
  const TrackerParams& params() const;
  /// Tracks ever created, and deleted (timed out).
  int tracks_created() const;
  int tracks_deleted() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace romo::objects
