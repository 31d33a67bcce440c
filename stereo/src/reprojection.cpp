#include "romo/stereo/reprojection.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "romo/core/check.hpp"

namespace romo::stereo {

void ReprojectionParams::Validate() const {
  if (!(sigma_d_px >= 0.0) || !std::isfinite(sigma_d_px)) {
    Fail("ReprojectionParams.sigma_d_px = " + std::to_string(sigma_d_px) + ": must be finite and >= 0");
  }
  if (!(max_range_m > 0.0)) {
    Fail("ReprojectionParams.max_range_m = " + std::to_string(max_range_m) + ": must be > 0");
  }
  if (!(min_outline_step_px >= 0.0) || !std::isfinite(min_outline_step_px)) {
    Fail("ReprojectionParams.min_outline_step_px = " + std::to_string(min_outline_step_px) +
         ": must be finite and >= 0");
  }
  if (!(max_disparity_spread >= 0.0) || !std::isfinite(max_disparity_spread)) {
    Fail("ReprojectionParams.max_disparity_spread = " + std::to_string(max_disparity_spread) +
         ": must be finite and >= 0");
  }
}

PointCloud ReprojectDisparity(const cv::Mat& disparity, int subpixel_scale, int invalid_disparity,
                              const cv::Mat& intensity, const RectifiedGeometry& geometry,
                              const ReprojectionParams& params, const Eigen::Isometry3d& T_out_rig) {
  params.Validate();
  if (disparity.type() != CV_16SC1 && disparity.type() != CV_8UC1) {
    Fail("ReprojectDisparity: disparity type " + std::to_string(disparity.type()) +
         " (expected CV_16SC1 or CV_8UC1)");
  }
  if (!intensity.empty() && (intensity.type() != CV_8UC1 || intensity.size() != disparity.size())) {
    Fail("ReprojectDisparity: intensity image must be CV_8UC1 of the disparity's size " +
         std::to_string(disparity.cols) + "x" + std::to_string(disparity.rows));
  }
  if (subpixel_scale <= 0) Fail("ReprojectDisparity: subpixel_scale " + std::to_string(subpixel_scale) + " must be > 0");
  const double f = geometry.focal_px, b = geometry.baseline_m;
  if (!(f > 0.0) || !(b > 0.0)) {
    Fail("ReprojectDisparity: focal " + std::to_string(f) + " px and baseline " + std::to_string(b) +
         " m must be > 0");
  }
  // One affine map from the rectified frame into the output frame.
  Eigen::Isometry3d T_rig_rect = Eigen::Isometry3d::Identity();
  T_rig_rect.linear() = geometry.R_rig_rect;
  const Eigen::Isometry3f T = (T_out_rig * T_rig_rect).cast<float>();
  const Eigen::Matrix3f A = T.linear();
  const Eigen::Vector3f t = T.translation();

  const float bf = static_cast<float>(b * f);
  const float inv_scale = 1.f / static_cast<float>(subpixel_scale);
  const float cx = static_cast<float>(geometry.cx_px), cy = static_cast<float>(geometry.cy_px);
  const float sigma_factor = static_cast<float>(params.sigma_d_px) / bf;  // sigma_z = Z^2 * this
  const float max_range2 = static_cast<float>(params.max_range_m * params.max_range_m);
  const bool is16 = disparity.type() == CV_16SC1;
  const auto raw_at = [&](int v, int u) -> int {
    return is16 ? disparity.at<short>(v, u) : disparity.at<std::uint8_t>(v, u);
  };
  const float max_spread = static_cast<float>(params.max_disparity_spread);
  const float min_step_raw = static_cast<float>(params.min_outline_step_px) * static_cast<float>(subpixel_scale);
  // True when the valid disparities around (v, u) span more than max_spread of @p raw (and more
  // than the floor).
  const auto on_outline = [&](int v, int u, int raw) {
    int lo = raw, hi = raw;
    for (int dv = -1; dv <= 1; ++dv) {
      const int vv = v + dv;
      if (vv < 0 || vv >= disparity.rows) continue;
      for (int du = -1; du <= 1; ++du) {
        const int uu = u + du;
        if (uu < 0 || uu >= disparity.cols) continue;
        const int r = raw_at(vv, uu);
        if (r == invalid_disparity || r <= 0) continue;
        lo = std::min(lo, r);
        hi = std::max(hi, r);
      }
    }
    return static_cast<float>(hi - lo) > std::max(min_step_raw, max_spread * static_cast<float>(raw));
  };

  PointCloud cloud;
  cloud.Resize(static_cast<std::size_t>(disparity.total()));
  std::size_t n = 0;
  for (int v = 0; v < disparity.rows; ++v) {
    const short* row16 = is16 ? disparity.ptr<short>(v) : nullptr;
    const std::uint8_t* row8 = is16 ? nullptr : disparity.ptr<std::uint8_t>(v);
    const std::uint8_t* grey = intensity.empty() ? nullptr : intensity.ptr<std::uint8_t>(v);
    for (int u = 0; u < disparity.cols; ++u) {
      const int raw = is16 ? row16[u] : row8[u];
      if (raw == invalid_disparity || raw <= 0) continue;
      if (max_spread > 0.f && on_outline(v, u, raw)) continue;
      const float d = static_cast<float>(raw) * inv_scale;
      // Eq. 2.2 (pixel units): Z = b f / d, X = b (u - u0) / d, Y = b (v - v0) / d.
      const float z = bf / d;
      const Eigen::Vector3f p_rect(z * (static_cast<float>(u) - cx) / static_cast<float>(f),
                                   z * (static_cast<float>(v) - cy) / static_cast<float>(f), z);
      if (p_rect.squaredNorm() > max_range2) continue;
      const auto c = static_cast<Eigen::Index>(n);
      cloud.xyz.col(c) = A * p_rect + t;
      cloud.sigma_z_m[n] = z * z * sigma_factor;  // eq. 2.3
      cloud.intensity[n] = grey ? static_cast<float>(grey[u]) : 0.f;
      ++n;
    }
  }
  cloud.Resize(n);
  return cloud;
}

}  // namespace romo::stereo
