#include "romo/mapping/ground_removal.hpp"

#include <algorithm>
#include <cmath>

#include "internal/voxel_keys.hpp"
#include "romo/core/check.hpp"

namespace romo::mapping {

PlaneRansacParams GroundRemovalParams::DefaultRansac() {
  PlaneRansacParams p;
  p.inlier_threshold_m = 0.05f;
  p.axis = Eigen::Vector3f::UnitZ();
  p.max_axis_angle_rad = 0.1745f;  // 10 deg: slopes and pitch of a road vehicle stay below this
  p.max_iterations = 500;
  return p;
}

void GroundRemovalParams::Validate() const {
  const FieldCheck check("GroundRemovalParams");
  if (!std::isfinite(prior_height_m)) check.Fail("prior_height_m", prior_height_m, "must be finite");
  check.Positive("search_band_m", search_band_m);
  check.NonNegative("height_tolerance_m", height_tolerance_m);
  if (!(below_tolerance_m >= 0.f)) check.Fail("below_tolerance_m", below_tolerance_m, "must be >= 0 (or infinite)");
  check.NonNegative("below_sigmas", below_sigmas);
  if (min_inliers < 3) check.Fail("min_inliers", min_inliers, "must be >= 3");
  ransac.Validate();
}

GroundRemoval RemoveGround(const PointCloud& cloud, const GroundRemovalParams& params) {
  params.Validate();
  ROMO_THROW_UNLESS(cloud.IsConsistent());
  GroundRemoval out;
  out.plane.normal = Eigen::Vector3f::UnitZ();
  out.plane.d = -params.prior_height_m;

  const internal::FinitePoints finite = internal::GatherFinite(cloud.xyz, nullptr);
  out.skipped_non_finite = finite.skipped_non_finite;
  std::vector<int> candidates;
  for (int i : finite.indices) {
    if (std::abs(cloud.xyz(2, i) - params.prior_height_m) <= params.search_band_m) candidates.push_back(i);
  }
  if (static_cast<int>(candidates.size()) >= params.min_inliers) {
    const auto fit = FitPlaneRansac(cloud.xyz, params.ransac, &candidates);
    if (fit && static_cast<int>(fit->inliers.size()) >= params.min_inliers) {
      out.plane = fit->plane;
      out.refined = true;
      out.ransac_inliers = static_cast<int>(fit->inliers.size());
      out.ransac_iterations = fit->iterations;
    }
  }
  out.ground.reserve(candidates.size());
  out.obstacles.reserve(finite.indices.size() - candidates.size() / 2);
  for (int i : finite.indices) {
    // On or below the plane plus tolerance: ground (including noise under it), unless too deep.
    const float height = out.plane.SignedDistance(cloud.xyz.col(i));
    if (height < -std::max(params.below_tolerance_m, params.below_sigmas * cloud.sigma_z_m[i])) {
      out.below.push_back(i);
    } else if (height <= params.height_tolerance_m) {
      out.ground.push_back(i);
    } else {
      out.obstacles.push_back(i);
    }
  }
  if (!out.refined) {
    out.ransac_inliers = static_cast<int>(
        PlaneInliers(cloud.xyz, out.plane, params.ransac.inlier_threshold_m, &candidates).size());
  }
  return out;
}

}  // namespace romo::mapping
