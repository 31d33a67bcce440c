#pragma once
/// One general RANSAC plane fit (dissertation eq. 3.1, 3.2), used for the vehicle's ground and
/// the indoor supporting plane alike. Plane: n . p + d = 0 with |n| = 1.
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace romo::mapping {

struct Plane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  ///< unit normal
  float d = 0.f;                                      ///< offset, metres

  /// Signed distance of @p p in metres (positive on the normal's side).
  float SignedDistance(const Eigen::Vector3f& p) const { return normal.dot(p) + d; }
  /// (a, b, c, d) with unit (a, b, c).
  Eigen::Vector4f Coefficients() const { return {normal.x(), normal.y(), normal.z(), d}; }
  /// The plane through three points; nullopt when they are (nearly) collinear.
  static std::optional<Plane> Through(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1,
                                      const Eigen::Vector3f& p2);
};

struct PlaneRansacParams {
  /// A point is an inlier when |distance| <= this, metres.
  float inlier_threshold_m = 0.03f;
  /// p in eq. 3.2: probability that at least one sample is outlier-free.
  double success_probability = 0.99;
  /// eps in eq. 3.2 before anything is known; lowered adaptively as better planes are found.
  double initial_outlier_fraction = 0.9;
  /// Hard cap on the iterations eq. 3.2 asks for.
  int max_iterations = 2000;
  /// Optional constraint: the normal must lie within max_axis_angle_rad of +/-axis (e.g. the
  /// vehicle z for ground, gravity for a table). Unset: any orientation.
  std::optional<Eigen::Vector3f> axis;
  float max_axis_angle_rad = 0.2618f;  // 15 deg
  /// Re-fit the plane by least squares on the inliers (then recount them).
  bool refine = true;
  /// Fixed seed: results are reproducible.
  std::uint64_t seed = 0x5eed;

  /// @throws romo::Error naming the field and value when a field is out of range.
  void Validate() const;
};

struct PlaneFit {
  Plane plane;
  std::vector<int> inliers;  ///< indices into the input points, ascending
  int iterations = 0;        ///< samples drawn
};

/// N = log(1-p) / log(1-(1-eps)^s), eq. 3.2, rounded up and clamped to [1, max_iterations].
/// @throws romo::Error when p or eps is outside (0, 1) / [0, 1) or s < 1.
int RansacIterations(double success_probability, double outlier_fraction, int sample_size,
                     int max_iterations);

/// Fits a plane to @p xyz (3 x N, metres), optionally only to the points @p subset (indices into
/// xyz); non-finite points are ignored. If params.axis is set, the normal is oriented to the
/// axis's side (n . axis > 0); otherwise as found. Returns nullopt when fewer than 3 usable
/// points exist or no sample gives an admissible plane (an expected outcome, not an error).
/// @throws romo::Error on invalid @p params or an out-of-range subset index.
std::optional<PlaneFit> FitPlaneRansac(const Eigen::Matrix3Xf& xyz, const PlaneRansacParams& params,
                                       const std::vector<int>* subset = nullptr);

/// Least-squares plane (smallest-eigenvalue normal of the covariance) through @p indices of
/// @p xyz; nullopt when fewer than 3 points or degenerate.
std::optional<Plane> FitPlaneLeastSquares(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices);

/// Indices (ascending) of the finite points of @p xyz within @p threshold_m of @p plane,
/// optionally only among @p subset.
std::vector<int> PlaneInliers(const Eigen::Matrix3Xf& xyz, const Plane& plane, float threshold_m,
                              const std::vector<int>* subset = nullptr);

}  // namespace romo::mapping
