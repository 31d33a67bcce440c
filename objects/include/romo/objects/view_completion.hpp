#pragma once
/// Classification and completion of a vertical box seen from one viewpoint (dissertation 4.3.2:
/// object completion from class knowledge). Stereo sees only the faces turned to the cameras, so
/// along the line of sight a box's measured extent is only a lower bound of the object's; across
/// it the extent is measured. The class (and which footprint axis is its length) that explains the
/// measured extents best wins, the truncated extent is free up to the prior's maximum, and it is
/// then grown to the prior's mean away from the viewer: the near face, which was seen, stays put.
#include <optional>

#include <Eigen/Core>

#include "romo/objects/atlas.hpp"
#include "romo/objects/box.hpp"

namespace romo::objects {

struct ViewCompletionParams {
  /// A footprint axis within this angle of the line of sight has only its near face seen. At 45
  /// degrees (a corner view) both faces are seen whole, so the angle must stay below 45.
  double truncation_angle_deg = 40.0;
  /// When neither axis is that near the sight line but both are within this angle of it (a
  /// corner view), each axis in turn is read as the truncated one; 45 = off. Off by default: seen
  /// at a corner both faces show whole unless something cut one off, which only the scene around
  /// can tell (in a row of parked cars the neighbour or the field of view often does).
  double corner_angle_deg = 45.0;
  /// Objects nearer than this to the viewer are not completed (the line of sight is undefined).
  double min_range_m = 0.5;
  /// With a truncated extent, classes scoring within this factor of the best are equally likely
  /// (the hidden depth says nothing): the one needing the least completion wins (a pedestrian
  /// seen from the front is not completed into a cyclist).
  double ambiguity_ratio = 1.5;
  /// A footprint this thin across one axis (and at most face_max_aspect of the other) is one
  /// face of an object: its depth is hidden whatever the angle it is seen at, up to
  /// face_max_obliquity_deg off its normal (a car's rear seen obliquely by a side camera, its
  /// side hidden by the next car, is 1.8 m wide and 0.2 m deep with the sight line along its width).
  double face_max_thickness_m = 0.5;
  double face_max_aspect = 0.35;
  double face_max_obliquity_deg = 75.0;
  /// A class explains a lone face only with at least this score (stricter than the atlas's
  /// min_score): a narrow face is as well two people one behind the other along the sight line.
  double face_min_score = 0.3;
};

struct ViewedBox {
  Classification classification;
  Box3 box;                 ///< completed for classes with priors, the input box otherwise
  bool completed = false;   ///< an extent was grown
};

/// @param box vertical box (yaw about z, size = extents along axes.col(0), col(1), height), in
///        the same frame as @p viewer_xy (e.g. the vehicle frame with the cameras at its origin).
/// @param depth_spread_m how much depth noise widened the extent along the line of sight (e.g.
///        2 x 1.88 sigma_z for a fit that trims 3 % at each end): removed from the truncated
///        extent before scoring, and the near face moves back by half of it.
/// @throws romo::Error for non-finite extents or viewer, or a negative spread.
ViewedBox ClassifyFromViewpoint(const Atlas& atlas, const Box3& box, const Eigen::Vector2f& viewer_xy,
                                const ViewCompletionParams& params = {}, double depth_spread_m = 0.0);

/// The same for a class already known (e.g. voted by the box's track over earlier, fuller views):
/// the box is scored and completed as @p class_index only; it stays unknown when its extents
/// cannot be that class (a fragment too low or too long for it).
/// @param length_heading_rad the object's heading when known otherwise (the row a parked car
///        stands in): the footprint axis nearest it is the length, and it may be truncated (only
///        the near end seen) at any angle to the line of sight.
/// @throws romo::Error as above, for a class index outside the atlas or a non-finite heading.
ViewedBox CompleteAsClass(const Atlas& atlas, int class_index, const Box3& box, const Eigen::Vector2f& viewer_xy,
                          const ViewCompletionParams& params = {}, double depth_spread_m = 0.0,
                          std::optional<double> length_heading_rad = std::nullopt);

}  // namespace romo::objects
