#pragma once
/// The projected hand path ("fingerprint"), its encapsulation and the motion profiles
/// x(t), y(t), r(t) (Sec. 4.2.5).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "romo/indoor_manip/interaction_plane.hpp"

namespace romo::indoor_manip {

/// PCA: box axes from the principal components of the projected path;
/// PLN: axes fixed by the plane (x = camera x projected onto the plane).
enum class Encapsulation { kPca, kPln };
/// "pca" / "pln"; Parse throws romo::Error naming the text.
const char* ToString(Encapsulation e);
Encapsulation ParseEncapsulation(const std::string& text);

struct MotionProfiles {
  std::vector<double> t_s;
  std::vector<double> x_m;  ///< along the encapsulation's first axis
  std::vector<double> y_m;  ///< along its second axis
  std::vector<double> r_m;  ///< distance to the plane (eq. 4.5)
  std::size_t size() const { return t_s.size(); }
};

struct Fingerprint {
  Encapsulation encapsulation = Encapsulation::kPln;
  PlaneFrame frame;  ///< frame of the profiles (its origin = box centre)
  std::vector<Eigen::Vector3d> projected_m;  ///< c' per sample, camera frame (eq. 4.4)
  Eigen::Vector2d box_extent_m = Eigen::Vector2d::Zero();  ///< box side lengths in the plane
  double box_height_m = 0.0;  ///< extent of r
  MotionProfiles profiles;
};

/// Projects @p centroids_m (camera frame, one per @p t_s) onto @p plane and encapsulates them.
/// @throws romo::Error when the sizes differ or fewer than 2 samples are given.
Fingerprint BuildFingerprint(const std::vector<double>& t_s,
                             const std::vector<Eigen::Vector3d>& centroids_m,
                             const InteractionPlane& plane, Encapsulation encapsulation);

}  // namespace romo::indoor_manip
