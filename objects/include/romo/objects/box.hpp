#pragma once
/// Oriented boxes around blobs (dissertation Fig. 3.9): a PCA box with all three axes free, and a
/// vertical cuboid whose height axis is the ground normal (only yaw free) for pedestrians and cars.
///
/// Heading convention (stable frame to frame): length >= width, and without a hint the yaw lies
/// in [-pi/2, pi/2) — a box looks the same turned by 180 deg, so the half-open range picks one of
/// the two. With a hint (a tracker's previous yaw) the equivalent heading nearest the hint is
/// returned instead, so a track keeps its direction and a near-square box does not jump by 90 deg.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "romo/mapping/plane_ransac.hpp"

namespace romo::objects {

struct Box3 {
  /// Box centre (middle of the extents, not the point mean), metres, in the cloud's frame.
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  /// Extents along axes.col(0), col(1), col(2): length, width, height in metres.
  Eigen::Vector3f size = Eigen::Vector3f::Zero();
  /// Heading of axes.col(0) about the up axis, radians, counter-clockwise from the frame's x axis
  /// (for a PCA box: of col(0) projected onto the xy plane).
  float yaw_rad = 0.f;
  /// Columns: unit length, width and height directions (right-handed rotation matrix).
  Eigen::Matrix3f axes = Eigen::Matrix3f::Identity();

  /// Volume in cubic metres.
  float volume_m3() const { return size.prod(); }
  /// True when @p p (same frame) lies inside the box grown by @p margin_m on every side.
  bool Contains(const Eigen::Vector3f& p, float margin_m = 0.f) const;
  /// The 8 corners (columns), metres.
  Eigen::Matrix<float, 3, 8> Corners() const;
};

/// Full 3D PCA box of the points @p indices of @p xyz (3 x N, metres): axes are the principal
/// directions (largest variance first), extents the min/max projections. col(2) is flipped to
/// point up (+z) and col(0) canonicalised as in the header note.
/// @param hint_yaw_rad previous heading of the same object, optional: the box is turned about
///        col(2) by a multiple of 90 deg so that its yaw is the one nearest the hint, keeping
///        length >= width unless the footprint (length, width) is nearly square (as CanonicalYaw).
///        The yaw (of col(0) projected onto xy) only means a heading where col(2) is near vertical.
/// @throws romo::Error when @p indices is empty, out of range or names a non-finite point, or
///         for a non-finite @p hint_yaw_rad.
Box3 FitPcaBox(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices,
               std::optional<float> hint_yaw_rad = std::nullopt);

/// How FitVerticalBox's heading search (trim_fraction > 0) judges a heading.
enum class HeadingCriterion {
  kSmallestArea,  ///< the smallest trimmed footprint rectangle
  /// The rectangle whose sides the points lie closest to (the closeness criterion of L-shape
  /// fitting): a car's end face plus the part of its side seen obliquely, smeared by stereo
  /// noise, has no clearly smallest rectangle but two clear sides.
  kEdgeCloseness,
};

/// Vertical cuboid: height along @p up (unit ground normal, e.g. from ground removal), footprint
/// the minimum-area rectangle of the points projected onto the ground plane (rotating calipers
/// over the convex hull, exact for partly seen L-shaped car outlines where PCA is biased).
/// yaw_rad is measured about @p up from the frame's x axis projected onto the ground plane.
/// @param hint_yaw_rad previous heading of the same object (e.g. the track's yaw), optional.
/// @throws romo::Error when @p indices is empty, out of range, names a non-finite point, or
///         @p up is not a unit vector.
/// @param trim_fraction for noisy points (stereo at range): the fraction of points ignored at
///        each end of every axis, and the heading is the one whose trimmed footprint rectangle
///        is smallest (searched in 1 degree steps) instead of the exact hull's; 0 = exact fit.
/// @param criterion with trim_fraction > 0: how the searched heading is judged (HeadingCriterion).
Box3 FitVerticalBox(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices,
                    const Eigen::Vector3f& up = Eigen::Vector3f::UnitZ(),
                    std::optional<float> hint_yaw_rad = std::nullopt, float trim_fraction = 0.f,
                    HeadingCriterion criterion = HeadingCriterion::kSmallestArea);

/// The same cuboid with its heading given (e.g. estimated with the depth noise taken out): the
/// footprint's (trimmed) extents along @p yaw_rad and across it; the returned yaw is the
/// equivalent heading nearest @p yaw_rad.
/// @throws romo::Error as FitVerticalBox, or for a non-finite @p yaw_rad.
Box3 FitVerticalBoxAtHeading(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices, const Eigen::Vector3f& up,
                             float yaw_rad, float trim_fraction = 0.f);

/// How far the bottom of @p box (a vertical cuboid, height along @p ground's normal) lies above
/// @p ground; negative when it reaches below.
float HeightAboveGround(const Box3& box, const mapping::Plane& ground);

/// @p box (a vertical cuboid, height along @p ground's normal) reaching down to @p ground when its
/// bottom lies above it by at most @p max_gap_m: ground removal takes the lowest centimetres of
/// whatever stands on the ground along with the ground, so a car's or person's measured box floats
/// that far above it and comes out as much too short for its class. Boxes floating higher, or
/// reaching below the plane, are returned as they are.
/// @throws romo::Error for a negative or non-finite @p max_gap_m.
Box3 StandOnGround(Box3 box, const mapping::Plane& ground, float max_gap_m);

/// Heading (about z, in the xy plane) of points @p indices seen by stereo from @p viewer_xy, with
/// the depth noise taken out of their footprint's second moments: the points' covariance less
/// the mean of sigma_z^2 along each point's sight line. Far surfaces are smeared along the line
/// of sight (0.4 m at 11 m for half-resolution stereo), and a car's front seen obliquely becomes
/// a slab that the smallest rectangle follows instead of the face. Nothing when the spread along
/// the line of sight is not more than @p noise_dominated_fraction noise (then the rectangle fit
/// is the better one: it is exact for L-shaped outlines, where moments are biased).
/// @throws romo::Error for bad indices, a sigma_z count unlike the point count, a non-finite
///         viewer or a negative fraction.
std::optional<float> DenoisedHeading(const Eigen::Matrix3Xf& xyz, const std::vector<float>& sigma_z_m,
                                     const std::vector<int>& indices, const Eigen::Vector2f& viewer_xy,
                                     double noise_dominated_fraction);

/// Canonical heading for a footprint with extents (@p length_m, @p width_m) along a heading
/// @p yaw_rad: swaps length/width so length >= width and returns the yaw in [-pi/2, pi/2); with
/// @p hint_yaw_rad, returns the equivalent heading nearest the hint (within pi/2 of it), keeping
/// length >= width unless the footprint is nearly square (|l - w| < 10 %), where continuity wins.
float CanonicalYaw(float yaw_rad, float* length_m, float* width_m,
                   std::optional<float> hint_yaw_rad = std::nullopt);

}  // namespace romo::objects
