#pragma once
// A camera-frame point projected into the raw (distorted) image by OpenCV, independently of
// romo's own camera code: for tests that compare against rendered truth. Link opencv_calib3d.
#include <vector>

#include <Eigen/Core>
#include <opencv2/calib3d.hpp>

#include "romo/drivers/calibration.hpp"

namespace romo::test {

inline cv::Point2d ProjectToImage(const Eigen::Vector3d& p_cam, const drivers::CameraIntrinsics& cam) {
  cv::Mat K(3, 3, CV_64F), dist(1, static_cast<int>(cam.distortion.size()), CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) K.at<double>(r, c) = cam.K(r, c);
  }
  for (std::size_t i = 0; i < cam.distortion.size(); ++i) dist.at<double>(0, static_cast<int>(i)) = cam.distortion[i];
  std::vector<cv::Point3d> in = {{p_cam.x(), p_cam.y(), p_cam.z()}};
  std::vector<cv::Point2d> out;
  cv::projectPoints(in, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, cam.distortion.empty() ? cv::Mat() : dist, out);
  return out[0];
}

}  // namespace romo::test
