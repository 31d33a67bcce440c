#include "romo/core/point_cloud.hpp"
#include "romo/mapping/plane_ransac.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "internal/voxel_keys.hpp"
#include "romo/core/check.hpp"

namespace romo::mapping {
namespace {

void FailField(const char* field, double value, const char* rule) {
  std::ostringstream msg;
  msg << "PlaneRansacParams." << field << " = " << value << ": " << rule;
  Fail(msg.str());
}

bool AxisAdmissible(const Plane& plane, const PlaneRansacParams& params, float cos_limit) {
  if (!params.axis) return true;
  return std::abs(plane.normal.dot(*params.axis)) >= cos_limit;
}

std::size_t CountInliers(const Eigen::Matrix3Xf& xyz, const std::vector<int>& usable, const Plane& plane,
                         float threshold) {
  std::size_t count = 0;
  const Eigen::Vector3f n = plane.normal;
  for (int i : usable) {
    const float dist = n.x() * xyz(0, i) + n.y() * xyz(1, i) + n.z() * xyz(2, i) + plane.d;
    count += std::abs(dist) <= threshold ? 1 : 0;
  }
  return count;
}

}  // namespace

std::optional<Plane> Plane::Through(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1,
                                    const Eigen::Vector3f& p2) {
  const Eigen::Vector3f cross = (p1 - p0).cross(p2 - p0);
  const float norm = cross.norm();
  // Relative test: collinear samples give a normal dominated by rounding.
  const float scale = std::max((p1 - p0).squaredNorm(), (p2 - p0).squaredNorm());
  if (!(norm > 1e-6f * scale) || !std::isfinite(norm)) return std::nullopt;
  Plane plane;
  plane.normal = cross / norm;
  plane.d = -plane.normal.dot(p0);
  return plane;
}

void PlaneRansacParams::Validate() const {
  if (!(std::isfinite(inlier_threshold_m) && inlier_threshold_m > 0.f))
    FailField("inlier_threshold_m", inlier_threshold_m, "must be finite and > 0");
  if (!(success_probability > 0.0 && success_probability < 1.0))
    FailField("success_probability", success_probability, "must be in (0, 1)");
  if (!(initial_outlier_fraction >= 0.0 && initial_outlier_fraction < 1.0))
    FailField("initial_outlier_fraction", initial_outlier_fraction, "must be in [0, 1)");
  if (max_iterations < 1) FailField("max_iterations", max_iterations, "must be >= 1");
  if (axis && !(std::abs(axis->norm() - 1.f) < 1e-3f))
    FailField("axis (norm)", axis->norm(), "must be a unit vector");
  if (!(max_axis_angle_rad >= 0.f && max_axis_angle_rad <= 1.5708f))
    FailField("max_axis_angle_rad", max_axis_angle_rad, "must be in [0, pi/2]");
}

int RansacIterations(double success_probability, double outlier_fraction, int sample_size,
                     int max_iterations) {
  if (!(success_probability > 0.0 && success_probability < 1.0) ||
      !(outlier_fraction >= 0.0 && outlier_fraction < 1.0) || sample_size < 1 || max_iterations < 1) {
    std::ostringstream msg;
    msg << "RansacIterations: need p in (0,1), eps in [0,1), s >= 1, max >= 1; got p=" << success_probability
        << " eps=" << outlier_fraction << " s=" << sample_size << " max=" << max_iterations;
    Fail(msg.str());
  }
  const double all_inliers = std::pow(1.0 - outlier_fraction, sample_size);
  if (all_inliers >= 1.0) return 1;
  const double denom = std::log(1.0 - all_inliers);
  if (denom == 0.0) return max_iterations;  // (1-eps)^s underflows: as many as allowed
  const double n = std::ceil(std::log(1.0 - success_probability) / denom);
  return static_cast<int>(std::clamp(n, 1.0, static_cast<double>(max_iterations)));
}

std::optional<Plane> FitPlaneLeastSquares(const Eigen::Matrix3Xf& xyz, const std::vector<int>& indices) {
  if (indices.size() < 3) return std::nullopt;
  const PointScatter stats = ComputeScatter(xyz, indices);
  const Eigen::Vector3d& mean = stats.mean;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(stats.scatter);
  if (eig.info() != Eigen::Success) return std::nullopt;
  // A plane needs two clearly non-zero spreads; the normal is the smallest one's direction.
  if (!(eig.eigenvalues()(1) > 1e-12 * std::max(1.0, eig.eigenvalues()(2)))) return std::nullopt;
  Plane plane;
  plane.normal = eig.eigenvectors().col(0).cast<float>().normalized();
  plane.d = static_cast<float>(-eig.eigenvectors().col(0).normalized().dot(mean));
  return plane;
}

std::vector<int> PlaneInliers(const Eigen::Matrix3Xf& xyz, const Plane& plane, float threshold_m,
                              const std::vector<int>* subset) {
  internal::FinitePoints finite = internal::GatherFinite(xyz, subset);
  std::vector<int> out;
  for (int i : finite.indices) {
    if (std::abs(plane.SignedDistance(xyz.col(i))) <= threshold_m) out.push_back(i);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::optional<PlaneFit> FitPlaneRansac(const Eigen::Matrix3Xf& xyz, const PlaneRansacParams& params,
                                       const std::vector<int>* subset) {
  params.Validate();
  const std::vector<int> usable = internal::GatherFinite(xyz, subset).indices;
  if (usable.size() < 3) return std::nullopt;
  const float cos_limit = std::cos(params.max_axis_angle_rad);
  std::mt19937_64 rng(params.seed);
  std::uniform_int_distribution<std::size_t> pick(0, usable.size() - 1);

  std::optional<Plane> best;
  std::size_t best_count = 0;
  int needed = RansacIterations(params.success_probability, params.initial_outlier_fraction, 3,
                                params.max_iterations);
  int iterations = 0;
  for (; iterations < needed; ++iterations) {
    const std::size_t a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || b == c || a == c) continue;
    const auto plane = Plane::Through(xyz.col(usable[a]), xyz.col(usable[b]), xyz.col(usable[c]));
    if (!plane || !AxisAdmissible(*plane, params, cos_limit)) continue;
    const std::size_t count = CountInliers(xyz, usable, *plane, params.inlier_threshold_m);
    if (count > best_count) {
      best_count = count;
      best = plane;
      // Eq. 3.2 with the outlier fraction this plane implies: fewer samples as it improves.
      const double eps = 1.0 - static_cast<double>(count) / static_cast<double>(usable.size());
      needed = std::min(needed, RansacIterations(params.success_probability, std::min(eps, 0.999999), 3,
                                                 params.max_iterations));
    }
  }
  if (!best) return std::nullopt;

  PlaneFit fit;
  fit.plane = *best;
  fit.iterations = iterations;
  fit.inliers = PlaneInliers(xyz, fit.plane, params.inlier_threshold_m, &usable);
  if (params.refine && fit.inliers.size() >= 3) {
    const auto refined = FitPlaneLeastSquares(xyz, fit.inliers);
    if (refined && AxisAdmissible(*refined, params, cos_limit)) {
      std::vector<int> again = PlaneInliers(xyz, *refined, params.inlier_threshold_m, &usable);
      if (again.size() >= fit.inliers.size()) {
        fit.plane = *refined;
        fit.inliers = std::move(again);
      }
    }
  }
  if (params.axis && fit.plane.normal.dot(*params.axis) < 0.f) {
    fit.plane.normal = -fit.plane.normal;
    fit.plane.d = -fit.plane.d;
  }
  return fit;
}

}  // namespace romo::mapping
