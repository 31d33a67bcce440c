#pragma once
/// Ego-motion between two RGB-D frames (Sec. 3.5): 2D features (ORB, AKAZE or SIFT; SURF is not
/// in this OpenCV), matched and lifted to 3D with Kinect depth covariances, then RANSAC with
/// Mahalanobis gating (romo::mapping::EstimateRigidMotion).
#include <optional>
#include <string>

#include "romo/indoor_manip/rgbd_image.hpp"
#include "romo/mapping/ego_motion.hpp"

namespace romo::indoor_manip {

enum class FeatureKind { kOrb, kAkaze, kSift };
/// "orb" / "akaze" / "sift"; @throws romo::Error naming the text.
FeatureKind ParseFeatureKind(const std::string& text);

/// Kinect v1 axial depth noise (Nguyen, Izadi, Lovell 2012), metres.
double KinectDepthSigmaM(double z_m);

struct OdometryParams {
  FeatureKind features = FeatureKind::kOrb;
  int max_features = 1500;
  /// Lowe's ratio test on the two nearest descriptors.
  double ratio = 0.8;
  /// Lateral point sigma from feature localisation, pixels.
  double pixel_sigma_px = 1.0;
  mapping::EgoMotionParams ransac;
  void Validate() const;
};

/// Matched features of @p a and @p b with valid depth, as 3D points with covariances.
mapping::MatchedPoints3D MatchRgbdFeatures(const RgbdImage& a, const RgbdImage& b,
                                           const DepthIntrinsics& intrinsics,
                                           const OdometryParams& params);

/// T_b_a (maps points of frame a's camera into frame b's) with inliers/outliers; nullopt when too
/// few matches support a motion.
std::optional<mapping::RigidMotion> EstimateEgoMotion(const RgbdImage& a, const RgbdImage& b,
                                                      const DepthIntrinsics& intrinsics,
                                                      const OdometryParams& params,
                                                      mapping::MatchedPoints3D* matches_out = nullptr);

}  // namespace romo::indoor_manip
