#pragma once
/// The interaction plane (whiteboard, table) and the projection of hand centroids onto it.
#include <Eigen/Core>

namespace romo::indoor_manip {

/// Plane n.p + d = 0 with |n| = 1, oriented so the camera origin lies on the positive side.
struct InteractionPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double d_m = 0.0;

  /// Normalises (a, b, c, d) and orients it towards the camera origin.
  /// @throws romo::Error when the normal is degenerate.
  static InteractionPlane FromCoefficients(const Eigen::Vector4d& abcd);
  /// Plane through three points. @throws romo::Error when they are (nearly) collinear.
  static InteractionPlane FromPoints(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                     const Eigen::Vector3d& c);

  /// Signed perpendicular distance r = c.n + d (eq. 4.5).
  double Distance(const Eigen::Vector3d& c) const { return c.dot(normal) + d_m; }
  /// Projection c' = c - (c.n + d) n (eq. 4.4).
  Eigen::Vector3d Project(const Eigen::Vector3d& c) const { return c - Distance(c) * normal; }
};

/// A right-handed frame on the plane: x and y in the plane, z = the plane normal.
struct PlaneFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();
  Eigen::Vector3d z_axis = Eigen::Vector3d::UnitZ();

  /// Rotation whose columns are the axes (maps frame coordinates into camera coordinates).
  Eigen::Matrix3d R_camera_frame() const;
  /// Point in frame coordinates.
  Eigen::Vector3d ToFrame(const Eigen::Vector3d& p_camera) const;
};

/// "PLN" frame: x = the camera x axis projected onto the plane (rows of writing run along it),
/// origin = the projection of @p origin_hint.
PlaneFrame PlaneAlignedFrame(const InteractionPlane& plane, const Eigen::Vector3d& origin_hint);

}  // namespace romo::indoor_manip
