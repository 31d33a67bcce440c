#include "romo/indoor_manip/manip_session.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "romo/core/check.hpp"
#include "romo/mapping/plane_picking.hpp"

namespace romo::indoor_manip {
namespace {

std::vector<int> ParseInts(const std::string& text, const std::string& what) {
  std::vector<int> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stoi(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      Fail(what + ": '" + text + "' has a bad integer '" + item + "'");
    }
  }
  return v;
}

}  // namespace

PlaneChoice PlaneChoice::Parse(const std::string& text) {
  PlaneChoice c;
  if (text == "auto") return c;
  const auto v = ParseInts(text, "--plane");
  if (v.size() != 6) Fail("--plane: '" + text + "' is neither 'auto' nor u1,v1,u2,v2,u3,v3");
  c.automatic = false;
  for (int i = 0; i < 3; ++i) c.pixels[i] = cv::Point(v[2 * i], v[2 * i + 1]);
  return c;
}

cv::Point ParsePixel(const std::string& text, const std::string& what) {
  const auto v = ParseInts(text, what);
  if (v.size() != 2) Fail(what + ": '" + text + "' is not u,v");
  return {v[0], v[1]};
}

Eigen::Matrix3Xf OrganizedCloud(const RgbdImage& image, const DepthIntrinsics& k) {
  const int w = image.width(), h = image.height();
  Eigen::Matrix3Xf xyz(3, static_cast<Eigen::Index>(w) * h);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < h; ++v) {
    const float* z = image.depth_m.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const Eigen::Index i = static_cast<Eigen::Index>(v) * w + u;
      if (z[u] > 0.f) {
        xyz.col(i) = k.Unproject(u, v, z[u]).cast<float>();
      } else {
        xyz.col(i).setConstant(nan);
      }
    }
  }
  return xyz;
}

InteractionPlane ChooseInteractionPlane(const RgbdImage& image, const DepthIntrinsics& k,
                                        const PlaneChoice& choice) {
  const Eigen::Matrix3Xf xyz = OrganizedCloud(image, k);
  // 1 cm: three Kinect depth sigmas at 1.5 m, well below the height of a hand above the plane.
  constexpr float kInlierM = 0.01f;
  mapping::Plane plane;
  if (choice.automatic) {
    mapping::MultiPlaneParams params;
    params.ransac.inlier_threshold_m = kInlierM;
    params.max_planes = 1;
    params.min_inliers = std::max(50, static_cast<int>(0.1 * image.width() * image.height()));
    const auto planes = mapping::FindPlanes(xyz, params);
    if (planes.empty()) {
      Fail("no interaction plane found by RANSAC (need " + std::to_string(params.min_inliers) +
           " inliers within " + std::to_string(kInlierM) + " m): pick three pixels with --plane");
    }
    plane = planes.front().plane;
  } else {
    std::array<Eigen::Vector2i, 3> px;
    for (int i = 0; i < 3; ++i) px[i] = {choice.pixels[i].x, choice.pixels[i].y};
    plane = mapping::PlaneFromPickedPixels(xyz, image.width(), px, kInlierM).plane;
  }
  return InteractionPlane::FromCoefficients(plane.Coefficients().cast<double>());
}

ManipResult AnalyzeSource(drivers::FrameSource& source, const DepthIntrinsics& intrinsics,
                          const SessionOptions& options, const std::string& origin) {
  std::unique_ptr<ManipAnalyzer> analyzer;
  int done = 0;
  while (options.max_frames <= 0 || done < options.max_frames) {
    auto set = source.Next();
    if (!set) break;
    if (!set->rgbd) Fail(origin + ": frame " + std::to_string(set->sequence) + " has no RGB-D image");
    const RgbdImage image = ToRgbdImage(*set->rgbd, origin + " frame " + std::to_string(done));
    if (!analyzer) {
      const InteractionPlane plane = ChooseInteractionPlane(image, intrinsics, options.plane);
      analyzer = std::make_unique<ManipAnalyzer>(plane, intrinsics, options.params);
    }
    analyzer->AddFrame(image, options.hand_seed);
    ++done;
    if (options.on_frame) options.on_frame(done);
  }
  if (!analyzer) Fail(origin + ": the source delivered no frame");
  return analyzer->Finish();
}

}  // namespace romo::indoor_manip
