#pragma once
/// The manipulation plugin: per frame hand segmentation + Kalman tracking + rotation; at the end
/// the fingerprint, motion profiles, features and the action label.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "romo/indoor_manip/action_label.hpp"
#include "romo/indoor_manip/fingerprint.hpp"
#include "romo/indoor_manip/hand_kalman.hpp"
#include "romo/indoor_manip/hand_rotation.hpp"
#include "romo/indoor_manip/hand_segmentation.hpp"
#include "romo/indoor_manip/interaction_plane.hpp"
#include "romo/indoor_manip/location_areas.hpp"
#include "romo/indoor_manip/object_map.hpp"
#include "romo/indoor_manip/rgbd_image.hpp"
#include "romo/indoor_manip/scene_objects.hpp"

namespace romo::indoor_manip {

struct ManipParams {
  HandSegmentationParams hand;
  HandKalmanParams kalman;
  RotationParams rotation;
  ActionThresholds thresholds;
  LocationParams location;
  SceneObjectParams scene;
  /// Independent motions of the scene's objects between the first and the last frame (feature
  /// flows + ICP); off: none are estimated.
  bool object_motions = true;
  OdometryParams odometry;
  mapping::IcpParams icp;
  /// The blob map over the frames (object completion with confidence values, Sec. 3.4): the
  /// objects of every object_map.every_frames-th frame with a hand, placed by the ego-motion
  /// (odometry); off: no completed objects.
  bool object_map = true;
  ObjectMapParams map;
  Encapsulation encapsulation = Encapsulation::kPln;
  /// Frames after which a lost hand ends tracking (the path keeps the predictions until then).
  int max_lost_frames = 15;
  void Validate() const;
};

/// One frame of the hand path: measured (may be missing), predicted and corrected centroids.
struct PathSample {
  double t_s = 0.0;
  bool measured = false;
  Eigen::Vector3d measured_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d predicted_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d corrected_m = Eigen::Vector3d::Zero();
  int hand_pixels = 0;
};

struct ManipResult {
  std::vector<PathSample> path;
  Fingerprint fingerprint;
  std::vector<Eigen::Vector3d> rotation_steps_rad;  ///< per frame pair, hand frame x, y, z
  ActionFeatures features;
  ActionDecision decision;
  /// Location areas on the plane (stays and ends of transport paths) with the transports.
  LocationAnalysis locations;
  /// The geometric layer on the first frame: plane inliers, blobs (octree DFS) with PCA boxes.
  SceneGeometry scene;
  /// Independent motions of the first frame's objects by the last frame.
  std::vector<ObjectMotion> object_motions;
  /// The blob map's objects (world frame = the first frame's camera), first-frame ones first.
  std::vector<CompletedObject> completed_objects;
  ObjectMapStats object_map;
  InteractionPlane plane;
  int frames = 0;
  int frames_without_hand = 0;
};

class ManipAnalyzer {
 public:
  /// @throws romo::Error for invalid params or intrinsics.
  ManipAnalyzer(const InteractionPlane& plane, const DepthIntrinsics& intrinsics,
                const ManipParams& params);
  ~ManipAnalyzer();
  ManipAnalyzer(const ManipAnalyzer&) = delete;
  ManipAnalyzer& operator=(const ManipAnalyzer&) = delete;

  /// Adds a frame. The first frame is segmented from @p seed (it throws romo::Error when the seed
  /// has no depth); later frames use the Kalman prediction. Returns the hand blob found, if any.
  std::optional<HandBlob> AddFrame(const RgbdImage& image, cv::Point seed);
  /// Fingerprint, profiles, features and label of everything added.
  /// @throws romo::Error when fewer than 2 frames had a hand.
  ManipResult Finish() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes fingerprint.png, profiles.png, rotation.png into @p dir (created if needed).
void WriteManipPlots(const ManipResult& result, const std::string& dir);
/// {"label": ..., "evidence": {features..., "reasons": [...]}, ...}
std::string ManipResultJson(const ManipResult& result);

}  // namespace romo::indoor_manip
