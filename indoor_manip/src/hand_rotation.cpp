#include "romo/indoor_manip/hand_rotation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

void RotationParams::Validate() const {
  if (!(max_depth_change_m > 0.0)) {
    Fail("rotation.max_depth_change_m must be > 0, got " + std::to_string(max_depth_change_m));
  }
  if (max_vectors < 3) Fail("rotation.max_vectors must be >= 3, got " + std::to_string(max_vectors));
  if (min_vectors < 3) Fail("rotation.min_vectors must be >= 3, got " + std::to_string(min_vectors));
  if (!(inlier_factor > 1.0)) Fail("rotation.inlier_factor must be > 1, got " + std::to_string(inlier_factor));
}

namespace {

// Rotation angle of the least-squares 2D rigid fit (Procrustes): after removing both centroids,
// tan(theta) = sum(a x b) / sum(a . b).
double FitAngle(const Eigen::Matrix2Xd& from, const Eigen::Matrix2Xd& to,
                const std::vector<char>& use) {
  Eigen::Vector2d ca = Eigen::Vector2d::Zero(), cb = Eigen::Vector2d::Zero();
  int n = 0;
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    if (!use[i]) continue;
    ca += from.col(i);
    cb += to.col(i);
    ++n;
  }
  if (n < 2) return 0.0;
  ca /= n;
  cb /= n;
  double sin_sum = 0.0, cos_sum = 0.0;
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    if (!use[i]) continue;
    const Eigen::Vector2d a = from.col(i) - ca;
    const Eigen::Vector2d b = to.col(i) - cb;
    sin_sum += a.x() * b.y() - a.y() * b.x();
    cos_sum += a.dot(b);
  }
  return std::atan2(sin_sum, cos_sum);
}

// Fit, gate residuals against the median (flow outliers at the hand's silhouette), refit.
double RobustAngle(const Eigen::Matrix2Xd& from, const Eigen::Matrix2Xd& to, double factor,
                   int* inliers) {
  std::vector<char> use(from.cols(), 1);
  const double theta = FitAngle(from, to, use);
  const Eigen::Rotation2Dd R(theta);
  const Eigen::Vector2d t = to.rowwise().mean() - R * from.rowwise().mean();
  std::vector<double> res(from.cols());
  for (Eigen::Index i = 0; i < from.cols(); ++i) res[i] = (to.col(i) - (R * from.col(i) + t)).norm();
  std::vector<double> sorted = res;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double gate = std::max(factor * sorted[sorted.size() / 2], 1e-4);
  int n = 0;
  for (Eigen::Index i = 0; i < from.cols(); ++i) {
    use[i] = res[i] <= gate;
    n += use[i];
  }
  *inliers = n;
  return FitAngle(from, to, use);
}

}  // namespace

double FitPlanarRotation(const Eigen::Matrix2Xd& from, const Eigen::Matrix2Xd& to) {
  ROMO_THROW_UNLESS(from.cols() == to.cols() && from.cols() >= 2);
  return FitAngle(from, to, std::vector<char>(from.cols(), 1));
}

RotationStep EstimateHandRotation(const RgbdImage& prev, const RgbdImage& next,
                                  const cv::Mat& mask_prev, const cv::Rect& bbox_prev,
                                  const DepthIntrinsics& k, const Eigen::Matrix3d& R_camera_hand,
                                  const RotationParams& params) {
  RotationStep step;
  const int pad = 16;  // room for the hand's motion between frames
  const cv::Rect roi = (cv::Rect(bbox_prev.x - pad, bbox_prev.y - pad, bbox_prev.width + 2 * pad,
                                 bbox_prev.height + 2 * pad)) &
                       cv::Rect(0, 0, prev.width(), prev.height());
  if (roi.width < 8 || roi.height < 8) return step;
  // A Kinect hand covers only a few hundred pixels: flow on a 2x upsampled window resolves its
  // texture, and an eroded mask keeps vectors off the silhouette, where the static background
  // drags the flow towards zero.
  constexpr double kScale = 2.0;
  cv::Mat prev_up, next_up, flow;
  cv::resize(prev.gray(roi), prev_up, cv::Size(), kScale, kScale, cv::INTER_LINEAR);
  cv::resize(next.gray(roi), next_up, cv::Size(), kScale, kScale, cv::INTER_LINEAR);
  cv::calcOpticalFlowFarneback(prev_up, next_up, flow, 0.5, 3, 11, 3, 5, 1.1, 0);
  cv::Mat mask;
  cv::erode(mask_prev(roi), mask, cv::Mat(), cv::Point(-1, -1), 1);
  if (cv::countNonZero(mask) < params.min_vectors) mask = mask_prev(roi);
  const int area = std::max(1, cv::countNonZero(mask));
  const int stride = std::max(1, static_cast<int>(std::sqrt(area / double(params.max_vectors))));
  std::vector<Eigen::Vector3d> p0, p1;
  for (int y = 0; y < roi.height; y += stride) {
    for (int x = 0; x < roi.width; x += stride) {
      if (mask.at<std::uint8_t>(y, x) == 0) continue;
      const int u = x + roi.x, v = y + roi.y;
      const float z0 = prev.depth_m.at<float>(v, u);
      const cv::Point2f fu = flow.at<cv::Point2f>(static_cast<int>(y * kScale), static_cast<int>(x * kScale));
      const cv::Point2f f(fu.x / kScale, fu.y / kScale);
      const float ue = u + f.x, ve = v + f.y;
      const int ui = static_cast<int>(std::lround(ue)), vi = static_cast<int>(std::lround(ve));
      if (ui < 0 || vi < 0 || ui >= next.width() || vi >= next.height()) continue;
      const float z1 = next.depth_m.at<float>(vi, ui);
      if (!(z0 > 0.f) || !(z1 > 0.f) || std::abs(z1 - z0) > params.max_depth_change_m) continue;
      p0.push_back(R_camera_hand.transpose() * k.Unproject(u, v, z0));
      p1.push_back(R_camera_hand.transpose() * k.Unproject(ue, ve, z1));
    }
  }
  step.vectors = static_cast<int>(p0.size());
  if (step.vectors < params.min_vectors) return step;
  // Project onto the plane perpendicular to each hand axis: (y,z) for x, (z,x) for y, (x,y) for z.
  static const int kA[3] = {1, 2, 0};
  static const int kB[3] = {2, 0, 1};
  int min_inliers = step.vectors;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Matrix2Xd a(2, p0.size()), b(2, p0.size());
    for (std::size_t i = 0; i < p0.size(); ++i) {
      a.col(i) << p0[i][kA[axis]], p0[i][kB[axis]];
      b.col(i) << p1[i][kA[axis]], p1[i][kB[axis]];
    }
    int inliers = 0;
    step.angle_rad[axis] = RobustAngle(a, b, params.inlier_factor, &inliers);
    min_inliers = std::min(min_inliers, inliers);
  }
  step.inliers = min_inliers;
  step.valid = min_inliers >= params.min_vectors;
  return step;
}

AngleHistogram MakeHistogram(const std::vector<double>& values_deg, double min_deg, double max_deg,
                             int bins) {
  ROMO_THROW_UNLESS(bins > 0 && max_deg > min_deg);
  AngleHistogram h;
  h.min_deg = min_deg;
  h.bin_deg = (max_deg - min_deg) / bins;
  h.counts.assign(bins, 0);
  for (double v : values_deg) {
    int i = static_cast<int>(std::floor((v - min_deg) / h.bin_deg));
    h.counts[std::clamp(i, 0, bins - 1)]++;
  }
  return h;
}

}  // namespace romo::indoor_manip
