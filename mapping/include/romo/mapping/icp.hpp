#pragma once
/// Point-to-point ICP (Besl & McKay): refines a rigid transform that maps a source cloud onto a
/// target cloud. Used to refine an object's independent motion found from feature flows
/// (Sec. 3.5.3): the flows give a coarse start, the dense blob points the fine fit.
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace romo::mapping {

struct IcpParams {
  int max_iterations = 50;
  /// Pairs farther apart than this after the current transform are ignored (metres). The start
  /// must be within about this distance of the truth.
  double max_correspondence_m = 0.03;
  /// Stop when an iteration moves the transform by less than this (metres / radians).
  double convergence_translation_m = 1e-5;
  double convergence_rotation_rad = 1e-5;
  /// Fewer pairs than this: no result.
  int min_pairs = 10;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

struct IcpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  double rmse_m = 0.0;  ///< over the final pairs
  int pairs = 0;
  int iterations = 0;
  bool converged = false;
};

/// Aligns @p source (3 x N) to @p target (3 x M), starting from @p initial. Nearest neighbours
/// come from a hash grid over the target (cell = max_correspondence_m). nullopt when fewer than
/// min_pairs pairs are within max_correspondence_m (an expected failure: bad start, no overlap).
/// @throws romo::Error for invalid params or non-finite points.
std::optional<IcpResult> AlignIcp(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                                  const Eigen::Isometry3d& initial, const IcpParams& params);

}  // namespace romo::mapping
