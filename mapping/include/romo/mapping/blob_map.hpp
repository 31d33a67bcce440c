#pragma once
/// Blob map over time (Sec. 3.4): intersection search between stored and new blobs (Alg. 1),
/// z-buffered re-projection of stored points into the current camera, Mahalanobis association in
/// a small pixel neighbourhood (3.3-3.7), Kalman point fusion (3.8-3.10), RANSAC rigid check
/// (3.11) propagated to every point of the blob (also the occluded ones), and per-point
/// confidence values with the four visibility cases (Fig. 3.16).
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/mapping/confidence.hpp"
#include "romo/mapping/ego_motion.hpp"

namespace romo::mapping {

/// Axis-aligned box in the world frame (kept for comparison: conservative for rotated objects).
struct Aabb {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e300);
  static Aabb Of(const Eigen::Matrix3Xd& xyz, double margin_m);
  bool Intersects(const Aabb& o) const {
    return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
  }
};

/// Oriented box (rectangular solid) in the world frame: the collision volume of Alg. 1.
struct Obb {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< columns: unit box axes
  Eigen::Vector3d half_m = Eigen::Vector3d::Zero();    ///< half extents along the axes
  /// The box along the points' principal axes, grown by @p margin_m on every side; empty input
  /// gives a box of half size @p margin_m at the origin.
  static Obb Of(const Eigen::Matrix3Xd& xyz, double margin_m);
  /// Separating-axis test over the 15 candidate axes of two boxes (3 + 3 face normals, 9 edge
  /// cross products); touching counts as intersecting.
  bool Intersects(const Obb& o) const;
};

/// Alg. 1: pairs (stored index, new index) whose oriented boxes collide.
std::vector<std::pair<int, int>> IntersectBlobs(const std::vector<Obb>& stored,
                                                const std::vector<Obb>& fresh);

struct PinholeCamera {
  double fx_px = 0, fy_px = 0, cx_px = 0, cy_px = 0;
  int width_px = 0, height_px = 0;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  void Validate() const;
};

/// One segmented blob of the current frame, world frame, with per-point covariances.
struct ObservedBlob {
  Eigen::Matrix3Xd xyz_world;
  std::vector<Eigen::Matrix3d> cov_world;
};

/// A stored blob: structure of arrays over its points.
struct Blob {
  int id = 0;
  Eigen::Matrix3Xd xyz_world;
  std::vector<Eigen::Matrix3d> cov_world;
  std::vector<PointEvidence> evidence;
  std::size_t size() const { return static_cast<std::size_t>(xyz_world.cols()); }
  /// Indices of the points whose confidence is at least @p min_cv.
  std::vector<int> ConfidentPoints(const ConfidenceParams& params, double min_cv) const;
};

struct BlobMapParams {
  /// chi^2 gate of eq. 3.4; 11.34 = 99% quantile for 3 degrees of freedom.
  double chi2_gate = 11.34;
  /// Half size of the pixel neighbourhood searched for a match (pixels).
  int search_radius_px = 2;
  /// A stored point is occluded when the current depth at its pixel is this much closer (m).
  double occlusion_margin_m = 0.03;
  /// Margin of the oriented boxes of the intersection search (m).
  double box_margin_m = 0.02;
  ConfidenceParams confidence;
  EgoMotionParams rigid;  ///< RANSAC of the rigid check (3.11)
  void Validate() const;
};

struct BlobMapUpdate {
  int intersections = 0;
  int matched = 0;
  int unpredicted = 0;  ///< observations added as new points
  /// Unmatched observations within the gate of a stored point of the same blob that matched a
  /// neighbouring observation: not added (no duplicate surface points).
  int redundant = 0;
  int unobserved = 0;
  int new_blobs = 0;
  /// Per stored blob updated: the rigid correction of eq. 3.11 applied to all its points.
  std::vector<std::pair<int, Eigen::Isometry3d>> corrections;
};

class BlobMap {
 public:
  explicit BlobMap(const BlobMapParams& params);

  /// Fuses the blobs of one frame. @p depth_m: the frame's full depth image (width*height,
  /// row-major, 0 = none) to tell occluded stored points from unobserved ones; may be empty.
  /// @throws romo::Error for an invalid camera or sizes that disagree.
  BlobMapUpdate Update(const std::vector<ObservedBlob>& blobs, const PinholeCamera& camera,
                       const std::vector<float>& depth_m);

  const std::vector<Blob>& blobs() const { return blobs_; }
  const BlobMapParams& params() const { return params_; }

 private:
  BlobMapParams params_;
  std::vector<Blob> blobs_;
  int next_id_ = 0;
};

}  // namespace romo::mapping
