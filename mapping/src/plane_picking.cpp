#include "romo/mapping/plane_picking.hpp"

#include <string>

#include "romo/core/check.hpp"

namespace romo::mapping {

void MultiPlaneParams::Validate() const {
  ransac.Validate();
  if (max_planes < 1) Fail("multi-plane max_planes must be >= 1, got " + std::to_string(max_planes));
  if (min_inliers < 3) Fail("multi-plane min_inliers must be >= 3, got " + std::to_string(min_inliers));
}

std::vector<PlaneFit> FindPlanes(const Eigen::Matrix3Xf& xyz, const MultiPlaneParams& params) {
  params.Validate();
  std::vector<int> remaining;
  remaining.reserve(xyz.cols());
  for (Eigen::Index i = 0; i < xyz.cols(); ++i) {
    if (xyz.col(i).allFinite()) remaining.push_back(static_cast<int>(i));
  }
  std::vector<PlaneFit> planes;
  PlaneRansacParams ransac = params.ransac;
  while (static_cast<int>(planes.size()) < params.max_planes &&
         static_cast<int>(remaining.size()) >= params.min_inliers) {
    auto fit = FitPlaneRansac(xyz, ransac, &remaining);
    if (!fit || static_cast<int>(fit->inliers.size()) < params.min_inliers) break;
    // Remove this plane's inliers (both lists ascending) and look for the next one.
    std::vector<int> rest;
    rest.reserve(remaining.size() - fit->inliers.size());
    std::size_t j = 0;
    for (int idx : remaining) {
      while (j < fit->inliers.size() && fit->inliers[j] < idx) ++j;
      if (j < fit->inliers.size() && fit->inliers[j] == idx) continue;
      rest.push_back(idx);
    }
    remaining.swap(rest);
    planes.push_back(std::move(*fit));
    ++ransac.seed;  // a fresh sample sequence per plane
  }
  return planes;
}

PlaneFit PlaneFromPickedPixels(const Eigen::Matrix3Xf& xyz, int width,
                               const std::array<Eigen::Vector2i, 3>& pixels,
                               float inlier_threshold_m) {
  ROMO_THROW_UNLESS(width > 0 && xyz.cols() % width == 0);
  const int height = static_cast<int>(xyz.cols() / width);
  std::array<Eigen::Vector3f, 3> p;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2i& px = pixels[i];
    const std::string name = "plane pixel " + std::to_string(i + 1) + " (" +
                             std::to_string(px.x()) + "," + std::to_string(px.y()) + ")";
    if (px.x() < 0 || px.y() < 0 || px.x() >= width || px.y() >= height) {
      Fail(name + " lies outside the " + std::to_string(width) + "x" + std::to_string(height) + " image");
    }
    p[i] = xyz.col(static_cast<Eigen::Index>(px.y()) * width + px.x());
    if (!p[i].allFinite()) Fail(name + " has no valid depth");
  }
  const auto plane = Plane::Through(p[0], p[1], p[2]);
  if (!plane) Fail("the three plane pixels are (nearly) collinear in 3D: pick a triangle");
  PlaneFit fit;
  fit.plane = *plane;
  fit.inliers = PlaneInliers(xyz, fit.plane, inlier_threshold_m);
  return fit;
}

}  // namespace romo::mapping
