#include "romo/indoor_manip/rgbd_image.hpp"

#include <cstdio>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

void DepthIntrinsics::Validate() const {
  if (!(fx_px > 0.0) || !(fy_px > 0.0)) {
    Fail("depth intrinsics: focal lengths must be positive, got fx=" + std::to_string(fx_px) +
         " fy=" + std::to_string(fy_px));
  }
}

DepthIntrinsics DepthIntrinsics::Parse(const std::string& text, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      Fail(what + ": '" + text + "' is not fx,fy,cx,cy (bad number '" + item + "')");
    }
  }
  if (v.size() != 4) Fail(what + ": '" + text + "' is not fx,fy,cx,cy (4 numbers)");
  DepthIntrinsics k{v[0], v[1], v[2], v[3]};
  k.Validate();
  return k;
}

std::optional<DepthIntrinsics> IntrinsicsFromSource(const drivers::FrameSource& source) {
  const drivers::Calibration* calib = source.calibration();
  if (calib == nullptr || calib->rigs.empty()) return std::nullopt;
  const Eigen::Matrix3d& K = calib->rigs.front().left.K;
  DepthIntrinsics k{K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
  if (!(k.fx_px > 1.0)) return std::nullopt;  // identity K = not calibrated
  return k;
}

RgbdImage ToRgbdImage(const drivers::RgbdFrame& frame, const std::string& origin) {
  frame.rgb.Validate();
  frame.depth.Validate();
  if (frame.depth.format != drivers::PixelFormat::kMono16) {
    Fail(origin + ": depth image must be mono16, got " +
         std::string(drivers::ToString(frame.depth.format)));
  }
  if (frame.rgb.width != frame.depth.width || frame.rgb.height != frame.depth.height) {
    Fail(origin + ": RGB is " + std::to_string(frame.rgb.width) + "x" +
         std::to_string(frame.rgb.height) + " but depth is " + std::to_string(frame.depth.width) +
         "x" + std::to_string(frame.depth.height) + " (register them first)");
  }
  if (!(frame.depth_scale_m > 0.0)) {
    Fail(origin + ": depth_scale_m must be positive, got " + std::to_string(frame.depth_scale_m));
  }
  RgbdImage out;
  out.stamp_ns = frame.stamp_ns;
  const int w = frame.depth.width;
  const int h = frame.depth.height;
  out.depth_m.create(h, w, CV_32FC1);
  int valid = 0;
  for (int y = 0; y < h; ++y) {
    const auto* src = reinterpret_cast<const std::uint16_t*>(frame.depth.row(y));
    float* dst = out.depth_m.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      dst[x] = static_cast<float>(src[x] * frame.depth_scale_m);
      valid += src[x] != 0;
    }
  }
  if (valid == 0) Fail(origin + ": depth image has no valid pixel (all zero)");
  if (frame.rgb.format == drivers::PixelFormat::kRgb8) {
    cv::Mat view(h, w, CV_8UC3, const_cast<std::uint8_t*>(frame.rgb.data.data()),
                 frame.rgb.stride_bytes);
    out.rgb = view.clone();
    cv::cvtColor(out.rgb, out.gray, cv::COLOR_RGB2GRAY);
  } else if (frame.rgb.format == drivers::PixelFormat::kMono8) {
    cv::Mat view(h, w, CV_8UC1, const_cast<std::uint8_t*>(frame.rgb.data.data()),
                 frame.rgb.stride_bytes);
    out.gray = view.clone();
    cv::cvtColor(out.gray, out.rgb, cv::COLOR_GRAY2RGB);
  } else {
    Fail(origin + ": colour image must be rgb8 or mono8, got " +
         std::string(drivers::ToString(frame.rgb.format)));
  }
  return out;
}

}  // namespace romo::indoor_manip
