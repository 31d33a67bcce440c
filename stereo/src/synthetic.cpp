#include "romo/stereo/synthetic.hpp"

#include <string>

#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"

namespace romo::stereo {

SyntheticPair RenderPlanePair(const RectifiedGeometry& g, int width, int height, const Eigen::Vector3d& normal,
                              double distance_m, std::uint32_t seed) {
  if (width <= 0 || height <= 0) Fail("RenderPlanePair: size must be positive");
  if (!(g.focal_px > 0.0) || !(g.baseline_m > 0.0)) Fail("RenderPlanePair: focal and baseline must be > 0");
  const Eigen::Vector3d n = normal.normalized();
  // d(u, v) = b/c * (n . (u - cx, v - cy, f)) is affine in u: d = a u + e(v).
  const double k = g.baseline_m / distance_m;
  const double a = k * n.x();
  if (a >= 1.0) Fail("RenderPlanePair: plane too oblique (disparity slope " + std::to_string(a) + ")");

  // Texture: random noise at half resolution, cubic upsampling gives 2-4 px blobs that SGM can
  // match and bilinear sampling reproduces accurately. A margin covers the right view's reach.
  const int margin = width;
  cv::Mat noise((height + 4) / 2, (width + 2 * margin) / 2, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::Mat texture;
  cv::resize(noise, texture, cv::Size(width + 2 * margin, height + 4), 0, 0, cv::INTER_CUBIC);

  SyntheticPair out;
  out.disparity_px.create(height, width, CV_32FC1);
  cv::Mat map_lx(height, width, CV_32FC1), map_rx(height, width, CV_32FC1), map_y(height, width, CV_32FC1);
  for (int v = 0; v < height; ++v) {
    const double e = k * (-n.x() * g.cx_px + n.y() * (v - g.cy_px) + n.z() * g.focal_px);
    for (int u = 0; u < width; ++u) {
      const double d = a * u + e;
      if (!(d > 0.0)) Fail("RenderPlanePair: the plane is not in front of the camera at pixel (" +
                           std::to_string(u) + ", " + std::to_string(v) + ")");
      out.disparity_px.at<float>(v, u) = static_cast<float>(d);
      map_lx.at<float>(v, u) = static_cast<float>(u + margin);
      // Right pixel u_r sees the left pixel u with u - d(u) = u_r.
      map_rx.at<float>(v, u) = static_cast<float>((u + e) / (1.0 - a) + margin);
      map_y.at<float>(v, u) = static_cast<float>(v + 2);
    }
  }
  cv::Mat lf, rf;
  cv::remap(texture, lf, map_lx, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  cv::remap(texture, rf, map_rx, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  lf.convertTo(out.left, CV_8U);
  rf.convertTo(out.right, CV_8U);
  return out;
}

}  // namespace romo::stereo
