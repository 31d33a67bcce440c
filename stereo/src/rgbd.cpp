#include "romo/stereo/rgbd.hpp"

#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"
#include "romo/stereo/multi_rig.hpp"

namespace romo::stereo {
namespace {

// Maps from destination pixels to source pixels: src = (dst - c_dst) * f_src / f_dst + c_src.
void WarpMaps(const PinholeIntrinsics& dst, const PinholeIntrinsics& src, cv::Size dst_size,
              cv::Mat* map_x, cv::Mat* map_y) {
  map_x->create(dst_size, CV_32FC1);
  map_y->create(dst_size, CV_32FC1);
  const double sx = src.fx / dst.fx, sy = src.fy / dst.fy;
  for (int j = 0; j < dst_size.height; ++j) {
    float* mx = map_x->ptr<float>(j);
    float* my = map_y->ptr<float>(j);
    const float v = static_cast<float>((j - dst.cy) * sy + src.cy);
    for (int i = 0; i < dst_size.width; ++i) {
      mx[i] = static_cast<float>((i - dst.cx) * sx + src.cx);
      my[i] = v;
    }
  }
}

}  // namespace

void PinholeIntrinsics::Validate(const char* what) const {
  if (!(fx > 0.0) || !(fy > 0.0) || !std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(cx) ||
      !std::isfinite(cy)) {
    Fail(std::string(what) + ": intrinsics fx = " + std::to_string(fx) + ", fy = " + std::to_string(fy) +
         ", cx = " + std::to_string(cx) + ", cy = " + std::to_string(cy) + " (need finite, f > 0)");
  }
}

void KinectModel::Validate() const {
  ir.Validate("KinectModel.ir");
  rgb.Validate("KinectModel.rgb");
  if (!(projector_baseline_m > 0.0)) {
    Fail("KinectModel.projector_baseline_m = " + std::to_string(projector_baseline_m) + ": must be > 0");
  }
  if (!(sigma_d_px >= 0.0)) Fail("KinectModel.sigma_d_px = " + std::to_string(sigma_d_px) + ": must be >= 0");
}

cv::Mat WarpDepthToRgb(const cv::Mat& depth, const KinectModel& kinect, cv::Size rgb_size) {
  kinect.Validate();
  if (depth.empty() || (depth.type() != CV_16UC1 && depth.type() != CV_32FC1)) {
    Fail("WarpDepthToRgb: depth must be a non-empty CV_16UC1 or CV_32FC1 image");
  }
  if (rgb_size.width <= 0 || rgb_size.height <= 0) Fail("WarpDepthToRgb: RGB size must be positive");
  cv::Mat mx, my, out;
  WarpMaps(kinect.rgb, kinect.ir, rgb_size, &mx, &my);  // eq. 2.4 then 2.5
  cv::remap(depth, out, mx, my, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

cv::Mat WarpRgbToDepth(const cv::Mat& rgb, const KinectModel& kinect, cv::Size depth_size) {
  kinect.Validate();
  if (rgb.empty()) Fail("WarpRgbToDepth: RGB image is empty");
  if (depth_size.width <= 0 || depth_size.height <= 0) Fail("WarpRgbToDepth: depth size must be positive");
  cv::Mat mx, my, out;
  WarpMaps(kinect.ir, kinect.rgb, depth_size, &mx, &my);  // eq. 2.6
  cv::remap(rgb, out, mx, my, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
}

PointCloud DepthToCloud(const drivers::RgbdFrame& frame, const KinectModel& kinect, double max_range_m) {
  kinect.Validate();
  if (frame.depth.format != drivers::PixelFormat::kMono16) {
    Fail(std::string("DepthToCloud: depth image is ") + drivers::ToString(frame.depth.format) +
         ", expected mono16");
  }
  if (!(frame.depth_scale_m > 0.0)) {
    Fail("DepthToCloud: depth_scale_m = " + std::to_string(frame.depth_scale_m) + ": must be > 0");
  }
  if (!(max_range_m > 0.0)) Fail("DepthToCloud: max_range_m = " + std::to_string(max_range_m) + ": must be > 0");
  const cv::Mat depth = ToGreyMat(frame.depth);
  cv::Mat grey;
  if (!frame.rgb.empty()) {
    const cv::Mat g = ToGreyMat(frame.rgb);
    const cv::Mat g8 = g.depth() == CV_8U ? g : cv::Mat();
    if (!g8.empty()) grey = WarpRgbToDepth(g8, kinect, depth.size());
  }
  const double bf = kinect.projector_baseline_m * kinect.ir.fx;
  PointCloud cloud;
  cloud.Resize(depth.total());
  std::size_t n = 0;
  for (int v = 0; v < depth.rows; ++v) {
    const std::uint16_t* row = depth.ptr<std::uint16_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (row[u] == 0) continue;
      const double z = row[u] * frame.depth_scale_m;
      const double x = (u - kinect.ir.cx) * z / kinect.ir.fx;
      const double y = (v - kinect.ir.cy) * z / kinect.ir.fy;
      if (x * x + y * y + z * z > max_range_m * max_range_m) continue;
      const auto c = static_cast<Eigen::Index>(n);
      cloud.xyz.col(c) = Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
      cloud.sigma_z_m[n] = static_cast<float>(z * z / bf * kinect.sigma_d_px);  // eq. 2.3
      cloud.intensity[n] = grey.empty() ? 0.f : static_cast<float>(grey.at<std::uint8_t>(v, u));
      ++n;
    }
  }
  cloud.Resize(n);
  return cloud;
}

}  // namespace romo::stereo
