#include "romo/indoor_manip/hand_segmentation.hpp"

#include <cmath>
#include <deque>
#include <limits>
#include <string>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

void HandSegmentationParams::Validate() const {
  if (!(max_neighbour_distance_m > 0.0)) {
    Fail("hand.max_neighbour_distance_m must be > 0, got " + std::to_string(max_neighbour_distance_m));
  }
  if (!(plane_margin_m >= 0.0)) Fail("hand.plane_margin_m must be >= 0, got " + std::to_string(plane_margin_m));
  if (!(max_radius_m > 0.0)) Fail("hand.max_radius_m must be > 0, got " + std::to_string(max_radius_m));
  if (min_pixels < 1) Fail("hand.min_pixels must be >= 1, got " + std::to_string(min_pixels));
  if (seed_search_radius_px < 0) {
    Fail("hand.seed_search_radius_px must be >= 0, got " + std::to_string(seed_search_radius_px));
  }
}

namespace {

bool IsForeground(const Eigen::Vector3d& p, const InteractionPlane* plane, double margin_m) {
  return plane == nullptr || plane->Distance(p) > margin_m;
}

// BFS over 4-neighbours: a pixel joins when it has depth, is off the plane, is within
// max_radius_m of the seed point and its 3D point is close to the neighbour it was reached from.
HandBlob Grow(const RgbdImage& image, const DepthIntrinsics& k, cv::Point seed,
              const InteractionPlane* plane, const HandSegmentationParams& params) {
  const int w = image.width();
  const int h = image.height();
  HandBlob blob;
  blob.seed = seed;
  blob.mask = cv::Mat::zeros(h, w, CV_8UC1);
  const float zs = image.depth_m.at<float>(seed);
  const Eigen::Vector3d seed_p = k.Unproject(seed.x, seed.y, zs);
  const double r2max = params.max_radius_m * params.max_radius_m;
  const double d2max = params.max_neighbour_distance_m * params.max_neighbour_distance_m;
  std::deque<cv::Point> queue{seed};
  blob.mask.at<std::uint8_t>(seed) = 255;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int minx = seed.x, maxx = seed.x, miny = seed.y, maxy = seed.y;
  static const int kDx[4] = {1, -1, 0, 0};
  static const int kDy[4] = {0, 0, 1, -1};
  while (!queue.empty()) {
    const cv::Point q = queue.front();
    queue.pop_front();
    const Eigen::Vector3d pq = k.Unproject(q.x, q.y, image.depth_m.at<float>(q));
    sum += pq;
    ++blob.pixel_count;
    minx = std::min(minx, q.x);
    maxx = std::max(maxx, q.x);
    miny = std::min(miny, q.y);
    maxy = std::max(maxy, q.y);
    for (int i = 0; i < 4; ++i) {
      const int nx = q.x + kDx[i];
      const int ny = q.y + kDy[i];
      if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
      std::uint8_t& m = blob.mask.at<std::uint8_t>(ny, nx);
      if (m != 0) continue;
      const float z = image.depth_m.at<float>(ny, nx);
      if (!(z > 0.f)) continue;
      const Eigen::Vector3d pn = k.Unproject(nx, ny, z);
      if ((pn - pq).squaredNorm() > d2max) continue;
      if ((pn - seed_p).squaredNorm() > r2max) continue;
      if (!IsForeground(pn, plane, params.plane_margin_m)) continue;
      m = 255;
      queue.emplace_back(nx, ny);
    }
  }
  blob.bbox = cv::Rect(minx, miny, maxx - minx + 1, maxy - miny + 1);
  blob.centroid_m = sum / blob.pixel_count;
  return blob;
}

}  // namespace

HandBlob GrowHandRegion(const RgbdImage& image, const DepthIntrinsics& intrinsics, cv::Point seed,
                        const InteractionPlane* plane, const HandSegmentationParams& params) {
  params.Validate();
  intrinsics.Validate();
  const std::string where = "hand seed (" + std::to_string(seed.x) + "," + std::to_string(seed.y) + ")";
  if (seed.x < 0 || seed.y < 0 || seed.x >= image.width() || seed.y >= image.height()) {
    Fail(where + " lies outside the " + std::to_string(image.width()) + "x" +
         std::to_string(image.height()) + " image");
  }
  const float z = image.depth_m.at<float>(seed);
  if (!(z > 0.f)) Fail(where + " has no valid depth");
  const Eigen::Vector3d p = intrinsics.Unproject(seed.x, seed.y, z);
  if (!IsForeground(p, plane, params.plane_margin_m)) {
    Fail(where + " lies on the interaction plane (distance " +
         std::to_string(plane->Distance(p)) + " m): pick a pixel on the hand");
  }
  return Grow(image, intrinsics, seed, plane, params);
}

std::optional<HandBlob> FindHandNear(const RgbdImage& image, const DepthIntrinsics& intrinsics,
                                     const Eigen::Vector3d& predicted_m,
                                     const InteractionPlane* plane,
                                     const HandSegmentationParams& params) {
  if (!(predicted_m.z() > 0.0)) return std::nullopt;
  const Eigen::Vector2d uv = intrinsics.Project(predicted_m);
  const int r = params.seed_search_radius_px;
  double best = std::numeric_limits<double>::infinity();
  cv::Point best_px(-1, -1);
  // The centroid of a hand lies inside its volume, not on its surface: compare against the
  // point nearest to it along each ray.
  for (int dy = -r; dy <= r; dy += 2) {
    for (int dx = -r; dx <= r; dx += 2) {
      const int x = static_cast<int>(std::lround(uv.x())) + dx;
      const int y = static_cast<int>(std::lround(uv.y())) + dy;
      if (x < 0 || y < 0 || x >= image.width() || y >= image.height()) continue;
      const float z = image.depth_m.at<float>(y, x);
      if (!(z > 0.f)) continue;
      const Eigen::Vector3d p = intrinsics.Unproject(x, y, z);
      if (!IsForeground(p, plane, params.plane_margin_m)) continue;
      const double d = (p - predicted_m).norm();
      if (d < best) {
        best = d;
        best_px = cv::Point(x, y);
      }
    }
  }
  if (best_px.x < 0 || best > params.max_radius_m) return std::nullopt;
  HandBlob blob = Grow(image, intrinsics, best_px, plane, params);
  if (blob.pixel_count < params.min_pixels) return std::nullopt;
  return blob;
}

}  // namespace romo::indoor_manip
