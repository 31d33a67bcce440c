#pragma once
/// The depth edges of a parking bay read off the ground seen through the gap between two parked
/// cars (dissertation 4.3.3): the painted front line, and the kerb or verge where the bay's
/// surface ends. The cars alone bound a bay only roughly: they stop 0.2-0.5 m short of the line
/// and their far ends are mostly completed from the Atlas, not seen. Paint and kerbs differ from
/// asphalt in brightness, not in height a stereo rig resolves (a 0.15 m kerb 8 m away), so both
/// edges are found on the grey values of the ground points, against the bay's own asphalt.
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "romo/core/point_cloud.hpp"

namespace romo::mapping {

/// Where to look: a strip on the ground (x, y of a frame whose z is up) across the row, through
/// the gap, in coordinates along its depth axis measured from @p center_m.
struct BayStrip {
  Eigen::Vector2d center_m = Eigen::Vector2d::Zero();  ///< the bay's centre as the cars bound it
  Eigen::Vector2d depth_axis = Eigen::Vector2d::UnitY();  ///< unit, from the aisle into the bay
  double half_width_m = 0.0;  ///< ground points this close to the strip's centre line count
  double front_m = 0.0;       ///< the neighbours' front (aisle side), along depth_axis
  double rear_m = 0.0;        ///< the neighbours' rear, along depth_axis
};

struct BayEdgeParams {
  double bin_m = 0.1;             ///< profile resolution along the depth axis
  int min_bin_points = 3;         ///< sparser bins are unknown
  int min_reference_points = 30;  ///< the bay's asphalt needs this many points, or nothing is found
  /// A painted line: bins at least this many times brighter than the asphalt, together no wider
  /// than max_paint_width_m, from front_search_m in front of the cars' fronts to front_behind_m
  /// behind them.
  double paint_contrast = 1.5;
  double max_paint_width_m = 0.4;
  double front_search_m = 1.0;
  double front_behind_m = 0.3;
  /// The bay's surface ends (kerb, verge, another paving) where surface_min_bins bins in a row
  /// are this many times brighter or darker than the asphalt, looked for from
  /// rear_search_before_m before the cars' rear to rear_search_after_m behind it.
  double surface_contrast = 1.25;
  int surface_min_bins = 2;
  double rear_search_before_m = 1.0;
  double rear_search_after_m = 1.5;

  /// @throws romo::Error naming the field and value when a value is out of range.
  void Validate() const;
};

struct BayEdges {
  std::optional<double> front_m;  ///< the bay's side of the painted front line, along depth_axis
  std::optional<double> rear_m;   ///< where the bay's surface ends, along depth_axis
  int reference_points = 0;       ///< asphalt points between the edges the cars give
  double reference_intensity = 0.0;  ///< their median grey value
};

/// Finds the edges on the points @p ground of @p cloud, mapped by @p T_frame_cloud into the
/// strip's frame. An edge not clearly seen is left empty: the caller keeps what the cars give.
/// @throws romo::Error on invalid @p params, a strip without a unit depth axis or a positive
/// width, or an index outside @p cloud.
BayEdges FindBayEdges(const PointCloud& cloud, const std::vector<int>& ground,
                      const Eigen::Isometry3d& T_frame_cloud, const BayStrip& strip,
                      const BayEdgeParams& params);

}  // namespace romo::mapping
