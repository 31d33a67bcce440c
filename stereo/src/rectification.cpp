#include "romo/stereo/rectification.hpp"

#include <cmath>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "romo/core/check.hpp"

namespace romo::stereo {
namespace {

// Largest angle between the two cameras' optical axes that still rectifies into a usable pair.
constexpr double kMaxRelativeRotationDeg = 30.0;
// Smallest useful baseline.
constexpr double kMinBaselineM = 1e-3;
// Smallest share of the image the rectified common view must cover.
constexpr double kMinValidAreaFraction = 0.25;

cv::Mat ToCv(const Eigen::Matrix3d& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.at<double>(r, c) = m(r, c);
  return out;
}

void CheckIntrinsics(const drivers::CameraIntrinsics& cam, const std::string& who) {
  const Eigen::Matrix3d& K = cam.K;
  if (!K.allFinite() || !(K(0, 0) > 0.0) || !(K(1, 1) > 0.0)) {
    Fail(who + ": camera matrix must be finite with fx, fy > 0 (fx = " + std::to_string(K(0, 0)) +
         ", fy = " + std::to_string(K(1, 1)) + ")");
  }
  for (double k : cam.distortion) {
    if (!std::isfinite(k)) Fail(who + ": distortion coefficient is not finite");
  }
  const std::size_t n = cam.distortion.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    Fail(who + ": " + std::to_string(n) + " distortion coefficients (OpenCV takes 4, 5, 8, 12 or 14)");
  }
}

}  // namespace

class Rectifier::Impl {
 public:
  cv::Mat map_lx, map_ly, map_rx, map_ry, Q;
  RectifiedGeometry geometry;
  int width = 0, height = 0;
};

Rectifier::Rectifier(const drivers::RigCalibration& rig) : impl_(std::make_unique<Impl>()) {
  const std::string who = "rig " + std::to_string(rig.rig_id) + " (" + rig.name + ")";
  if (rig.width_px <= 0 || rig.height_px <= 0) {
    Fail(who + ": image size " + std::to_string(rig.width_px) + "x" + std::to_string(rig.height_px) +
         " is not rectifiable");
  }
  CheckIntrinsics(rig.left, who + " left");
  CheckIntrinsics(rig.right, who + " right");
  if (!rig.R.allFinite() || !rig.T.allFinite()) Fail(who + ": R or T is not finite");
  const double orth_err = (rig.R * rig.R.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (orth_err > 1e-3 || rig.R.determinant() < 0.0) {
    Fail(who + ": R is not a rotation (|R R^T - I| = " + std::to_string(orth_err) + ")");
  }
  const double angle_deg = Eigen::AngleAxisd(rig.R).angle() * 180.0 / M_PI;
  if (angle_deg > kMaxRelativeRotationDeg) {
    Fail(who + ": not rectifiable: cameras rotated " + std::to_string(angle_deg) +
         " deg apart (max " + std::to_string(kMaxRelativeRotationDeg) + ")");
  }
  const double b = rig.T.norm();
  if (b < kMinBaselineM) Fail(who + ": not rectifiable: baseline " + std::to_string(b) + " m");
  // Horizontal stereo only: the right camera sits at +x of the left one, so T = (-b, 0, 0).
  if (std::abs(rig.T.x()) < std::hypot(rig.T.y(), rig.T.z())) {
    Fail(who + ": not rectifiable as a horizontal pair: T = (" + std::to_string(rig.T.x()) + ", " +
         std::to_string(rig.T.y()) + ", " + std::to_string(rig.T.z()) + ") m is mostly vertical/forward");
  }
  if (rig.T.x() > 0.0) {
    Fail(who + ": T.x = " + std::to_string(rig.T.x()) +
         " m > 0: the right camera is left of the left one (swapped cameras?)");
  }

  const cv::Size size(rig.width_px, rig.height_px);
  const cv::Mat K1 = ToCv(rig.left.K), K2 = ToCv(rig.right.K);
  const cv::Mat D1(rig.left.distortion, true), D2(rig.right.distortion, true);
  const cv::Mat R = ToCv(rig.R);
  const cv::Mat T = (cv::Mat_<double>(3, 1) << rig.T.x(), rig.T.y(), rig.T.z());
  cv::Mat R1, R2, P1, P2;
  cv::Rect roi1, roi2;
  // alpha 0: only pixels valid in both views, so the matcher never sees black borders.
  cv::stereoRectify(K1, D1, K2, D2, size, R, T, R1, R2, P1, P2, impl_->Q, cv::CALIB_ZERO_DISPARITY,
                    0.0, size, &roi1, &roi2);
  const double f = P1.at<double>(0, 0);
  const double tx = P2.at<double>(0, 3);  // -f * b for a horizontal pair
  if (!cv::checkRange(P1) || !cv::checkRange(P2) || !(f > 0.0) || !(tx < 0.0)) {
    Fail(who + ": stereoRectify produced no horizontal pair (f = " + std::to_string(f) + ")");
  }
  const double area = static_cast<double>((roi1 & roi2).area()) / size.area();
  if (area < kMinValidAreaFraction) {
    Fail(who + ": not rectifiable: the rectified views share only " + std::to_string(100.0 * area) +
         "% of the image");
  }
  cv::initUndistortRectifyMap(K1, D1, R1, P1, size, CV_16SC2, impl_->map_lx, impl_->map_ly);
  cv::initUndistortRectifyMap(K2, D2, R2, P2, size, CV_16SC2, impl_->map_rx, impl_->map_ry);
  RectifiedGeometry& g = impl_->geometry;
  g.focal_px = f;
  g.cx_px = P1.at<double>(0, 2);
  g.cy_px = P1.at<double>(1, 2);
  g.baseline_m = -tx / f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) g.R_rig_rect(r, c) = R1.at<double>(c, r);
  impl_->width = size.width;
  impl_->height = size.height;
}

Rectifier::~Rectifier() = default;
Rectifier::Rectifier(Rectifier&&) noexcept = default;
Rectifier& Rectifier::operator=(Rectifier&&) noexcept = default;

void Rectifier::Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_rect,
                        cv::Mat* right_rect) const {
  ROMO_THROW_UNLESS(left_rect != nullptr && right_rect != nullptr);
  for (const cv::Mat* img : {&left, &right}) {
    if (img->cols != impl_->width || img->rows != impl_->height) {
      Fail(std::string("Rectifier: ") + (img == &left ? "left" : "right") + " image is " +
           std::to_string(img->cols) + "x" + std::to_string(img->rows) + ", the calibration is " +
           std::to_string(impl_->width) + "x" + std::to_string(impl_->height));
    }
  }
  if (left.type() != right.type()) Fail("Rectifier: left and right images differ in type");
  cv::remap(left, *left_rect, impl_->map_lx, impl_->map_ly, cv::INTER_LINEAR);
  cv::remap(right, *right_rect, impl_->map_rx, impl_->map_ry, cv::INTER_LINEAR);
}

const RectifiedGeometry& Rectifier::geometry() const { return impl_->geometry; }
const cv::Mat& Rectifier::Q() const { return impl_->Q; }
int Rectifier::width() const { return impl_->width; }
int Rectifier::height() const { return impl_->height; }

}  // namespace romo::stereo
