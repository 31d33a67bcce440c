#pragma once
/// The geometric layer on one RGB-D frame (dissertation Sec. 3.2, Fig. 3.2): the points off the
/// interaction plane (foreground), an octree over them, blobs by depth-first search over occupied
/// leaves (romo::mapping::SegmentBlobs) and a PCA box per blob (romo::objects::FitPcaBox).
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "romo/indoor_manip/interaction_plane.hpp"
#include "romo/indoor_manip/rgbd_image.hpp"
#include "romo/indoor_manip/rgbd_odometry.hpp"
#include "romo/mapping/icp.hpp"
#include "romo/objects/box.hpp"

namespace romo::indoor_manip {

struct SceneObjectParams {
  /// Foreground: points at least this far above the plane, on the camera's side (metres). Twice
  /// the 1 cm plane inlier band: Kinect noise of the plane itself stays background.
  double min_height_m = 0.02;
  /// Octree leaf (metres): Kinect points at 1-1.5 m lie 2-3 mm apart, so 1.5 cm leaves join a
  /// surface across small depth holes but keep objects a few centimetres apart separate.
  float leaf_size_m = 0.015f;
  int min_blob_points = 60;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

struct SceneObject {
  int id = 0;
  objects::Box3 box;  ///< PCA box, camera frame
  int points = 0;
  double height_above_plane_m = 0.0;  ///< highest point's distance to the plane
  bool is_hand = false;  ///< the blob holding the hand seed pixel
  std::vector<int> pixels;  ///< its pixels (v * width + u), ascending
};

/// An object's independent rigid motion between two frames (outlier feature flows connecting its
/// blob in both frames, refined by ICP on the blobs' points).
struct ObjectMotion {
  int object_id = -1;  ///< SceneObject::id in the earlier frame
  Eigen::Isometry3d T_k1_k = Eigen::Isometry3d::Identity();  ///< frame-k points into frame k+1
  int feature_matches = 0;  ///< outlier flows linking the two blobs
  double icp_rmse_m = 0.0;
};

struct SceneGeometry {
  int plane_inliers = 0;  ///< points within 1 cm of the plane
  int foreground_points = 0;
  int occupied_leaves = 0;
  std::vector<SceneObject> objects;  ///< largest first
};

/// Plane inliers, foreground blobs and their PCA boxes of @p image. @p hand_seed (may lie outside
/// the image: no hand) marks the blob containing it.
SceneGeometry SegmentSceneObjects(const RgbdImage& image, const DepthIntrinsics& intrinsics,
                                  const InteractionPlane& plane, cv::Point hand_seed,
                                  const SceneObjectParams& params);

/// Independent motions between frames @p a and @p b (Sec. 3.5.3): features matched and lifted to
/// 3D, the camera's ego-motion by RANSAC, and for each object of @p ga the outlier flows that end
/// in one object of @p gb (the one most of them reach) give its coarse motion, refined by ICP
/// on the two blobs' points. Objects with fewer than odometry.ransac.min_inliers linking flows
/// are left out; an empty result when the ego-motion itself fails.
std::vector<ObjectMotion> EstimateObjectMotions(const RgbdImage& a, const SceneGeometry& ga,
                                                const RgbdImage& b, const SceneGeometry& gb,
                                                const DepthIntrinsics& intrinsics,
                                                const OdometryParams& odometry,
                                                const mapping::IcpParams& icp);

}  // namespace romo::indoor_manip
