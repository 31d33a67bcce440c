#pragma once
/// The blob map of the manipulation plugin (dissertation Sec. 3.4 on the objects of Sec. 3.2):
/// each frame's object blobs (off the interaction plane, octree DFS; the hand's blob left out)
/// are placed in the world frame by the camera's ego-motion and fused into a
/// romo::mapping::BlobMap. Per stored object: the completed box from its highest-confidence
/// points, the point counts per confidence band and the mean confidence.
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/indoor_manip/interaction_plane.hpp"
#include "romo/indoor_manip/rgbd_image.hpp"
#include "romo/indoor_manip/rgbd_odometry.hpp"
#include "romo/indoor_manip/scene_objects.hpp"
#include "romo/mapping/blob_map.hpp"
#include "romo/objects/box.hpp"

namespace romo::indoor_manip {

struct ObjectMapParams {
  mapping::BlobMapParams blobs;
  /// Fuse every n-th frame (1 = every frame); the ego-motion is estimated on those frames only.
  int every_frames = 2;
  /// The completed box is fitted to the points with a confidence value at least this: the top
  /// band (CV = 1 - exp(-so/2) >= 0.75 needs 3 supporting observations with alpha = 2).
  double completed_min_cv = 0.75;
  /// Fewer such points: no completed box.
  int min_completed_points = 20;
  /// Lateral sigma of a blob point: its pixel's footprint at its depth times this (pixels).
  double pixel_sigma_px = 1.0;
  /// Ego-motion against a keyframe (no drift for a still camera); below this many RANSAC
  /// inliers the previous fused frame becomes the keyframe.
  int min_keyframe_inliers = 12;
  /// No ego-motion features within this many pixels of the hand's blob (pixels).
  int hand_margin_px = 8;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

/// Confidence bands of the point counts: [0, 0.25), [0.25, 0.5), [0.5, 0.75), [0.75, 1].
inline constexpr std::array<double, 4> kConfidenceBandLow = {0.0, 0.25, 0.5, 0.75};

struct CompletedObject {
  int blob_id = -1;  ///< mapping::Blob::id
  /// SceneObject::id of the first frame's blob this stored blob started as; -1 when it appeared
  /// later.
  int first_frame_object = -1;
  int points = 0;
  std::array<int, 4> points_per_band{};  ///< see kConfidenceBandLow
  double mean_confidence = 0.0;
  int completed_points = 0;  ///< points with CV >= completed_min_cv
  /// Box of those points standing on the interaction plane (height along its normal, footprint
  /// the smallest rectangle: objects::FitVerticalBox), world frame (the first frame's camera);
  /// nullopt when fewer than min_completed_points.
  std::optional<objects::Box3> completed_box;
  /// Their PCA box (all three axes free), as the single-frame SceneObject::box.
  std::optional<objects::Box3> completed_pca_box;
};

struct ObjectMapStats {
  int frames_fused = 0;
  int ego_failures = 0;  ///< frames left out because no ego-motion was found
  int rekeys = 0;
  int matched = 0;       ///< stored points matched, over all frames
  int unpredicted = 0;   ///< observations added
  int unobserved = 0;    ///< predictions not observed
};

class ObjectMap {
 public:
  /// @p plane: the interaction plane in the first frame's camera (the world frame).
  /// @throws romo::Error for invalid params or intrinsics.
  ObjectMap(const DepthIntrinsics& intrinsics, const InteractionPlane& plane, const ObjectMapParams& params,
            const OdometryParams& odometry);
  ~ObjectMap();
  ObjectMap(const ObjectMap&) = delete;
  ObjectMap& operator=(const ObjectMap&) = delete;

  /// Fuses the non-hand objects of @p scene (segmented from @p image) when the frame is due
  /// (every_frames); returns whether it was fused. The first frame defines the world frame.
  bool Add(const RgbdImage& image, const SceneGeometry& scene);
  /// Whether the next Add() is due to fuse (callers may skip segmenting frames that are not).
  bool NextFrameIsDue() const;
  /// Counts a frame that is not fused (e.g. the hand could not be told from the objects).
  void Skip();
  /// The stored objects, first-frame ones first.
  std::vector<CompletedObject> Completed() const;
  const ObjectMapStats& stats() const;
  /// Camera pose of the last fused frame in the world frame.
  const Eigen::Isometry3d& T_world_camera() const;
  const mapping::BlobMap& blob_map() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace romo::indoor_manip
