#include "romo/indoor_manip/interaction_plane.hpp"

#include <Eigen/Geometry>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

InteractionPlane InteractionPlane::FromCoefficients(const Eigen::Vector4d& abcd) {
  const double norm = abcd.head<3>().norm();
  if (!(norm > 1e-9)) Fail("interaction plane: normal (a, b, c) is zero");
  InteractionPlane p;
  p.normal = abcd.head<3>() / norm;
  p.d_m = abcd[3] / norm;
  // The camera looks at the plane from its positive side: hand distances r come out positive.
  if (p.d_m < 0.0) {
    p.normal = -p.normal;
    p.d_m = -p.d_m;
  }
  return p;
}

InteractionPlane InteractionPlane::FromPoints(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                              const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double scale = (b - a).norm() * (c - a).norm();
  if (!(scale > 0.0) || n.norm() < 1e-3 * scale) {
    Fail("interaction plane: the three points are (nearly) collinear");
  }
  return FromCoefficients(Eigen::Vector4d(n.x(), n.y(), n.z(), -n.dot(a)));
}

Eigen::Matrix3d PlaneFrame::R_camera_frame() const {
  Eigen::Matrix3d R;
  R.col(0) = x_axis;
  R.col(1) = y_axis;
  R.col(2) = z_axis;
  return R;
}

Eigen::Vector3d PlaneFrame::ToFrame(const Eigen::Vector3d& p_camera) const {
  return R_camera_frame().transpose() * (p_camera - origin);
}

PlaneFrame PlaneAlignedFrame(const InteractionPlane& plane, const Eigen::Vector3d& origin_hint) {
  PlaneFrame f;
  f.z_axis = plane.normal;
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitX().dot(f.z_axis) * f.z_axis;
  if (x.norm() < 1e-6) {  // plane perpendicular to the camera x axis: use camera y instead
    x = Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitY().dot(f.z_axis) * f.z_axis;
  }
  f.x_axis = x.normalized();
  f.y_axis = f.z_axis.cross(f.x_axis);
  f.origin = plane.Project(origin_hint);
  return f;
}

}  // namespace romo::indoor_manip
