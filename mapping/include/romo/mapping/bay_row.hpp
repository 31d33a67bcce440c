#pragma once
/// A row of parking bays read off the paint on the ground: its front line and the separators
/// between the bays. Parked cars stand across the front line, between two separators; a car
/// 10-15 m off is seen only as an end smeared along the sight line, so its box follows the sight
/// line (40-60 deg off) and lands between two bays. The paint gives both its heading and its bay.
/// Paint differs from asphalt in brightness, not in height, so it is found on the grey values of
/// the ground points.
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "romo/core/point_cloud.hpp"

namespace romo::mapping {

struct BayRowParams {
  double max_range_m = 15.0;  ///< ground points farther from the origin (x, y) are not used
  /// Paint: at least this many times brighter than the median ground point in range.
  double contrast = 1.5;
  /// The front line: paint points this close to it are on it. Its length is that of the bins of
  /// line_bin_m along it that hold a point of it (cars standing on it, unseen stretches do not
  /// count); shorter than min_covered_m, it is no row's front (a separator, an arrow).
  double line_half_width_m = 0.1;
  double line_bin_m = 0.25;
  double min_covered_m = 6.0;
  int hypotheses = 300;              ///< pairs of paint points tried (RANSAC)
  double min_pair_distance_m = 2.0;  ///< closer pairs give too uncertain a direction
  int min_paint_points = 20;
  /// Separators: paint between separator_from_m and separator_to_m behind the front line (on
  /// the side holding more of it), gathered along the line in bins of separator_bin_m. A peak of
  /// at least separator_min_points points (within separator_half_width_m of it) spread over
  /// separator_min_depth_m along the bays' depth is a separator; of two closer than
  /// separator_min_spacing_m the one with more points stays.
  double separator_from_m = 0.2;
  double separator_to_m = 5.0;
  double separator_bin_m = 0.1;
  double separator_half_width_m = 0.15;
  int separator_min_points = 6;
  double separator_min_depth_m = 0.3;
  double separator_min_spacing_m = 1.5;
  /// The viewer (the frame's origin) stands in the aisle, and the bays lie beyond the front line;
  /// this close to the line it may be entering a bay, and the bays lie on the side showing more
  /// separators.
  double viewer_on_line_m = 3.0;

  /// @throws romo::Error naming the field and value when a value is out of range.
  void Validate() const;
};

struct BayRow {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< on the front line: the mean of its paint
  Eigen::Vector2d along = Eigen::Vector2d::UnitX();  ///< unit, along the front line
  Eigen::Vector2d into_bays = Eigen::Vector2d::UnitY();  ///< unit, from the aisle into the bays
  double covered_m = 0.0;  ///< length of the front line holding paint
  std::vector<double> separators_m;  ///< along the line from origin, ascending

  double Along(const Eigen::Vector2d& xy) const { return along.dot(xy - origin); }
  double Depth(const Eigen::Vector2d& xy) const { return into_bays.dot(xy - origin); }
  /// The bays' heading (into_bays) about z.
  double HeadingRad() const { return std::atan2(into_bays.y(), into_bays.x()); }
};

/// The row whose front line holds paint over the most length among the points @p ground of
/// @p cloud (x, y of a frame whose z is up), with the separators behind it; none without a
/// front line of min_covered_m, or when the longest line shows more separators on the viewer's
/// side (the bays' far end). Deterministic: the line's hypotheses are drawn from a fixed seed.
/// @throws romo::Error on invalid @p params or an index outside @p cloud.
std::optional<BayRow> FindBayRow(const PointCloud& cloud, const std::vector<int>& ground,
                                 const BayRowParams& params);

}  // namespace romo::mapping
