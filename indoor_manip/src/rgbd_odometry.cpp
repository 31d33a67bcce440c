#include "romo/indoor_manip/rgbd_odometry.hpp"

#include <opencv2/features2d.hpp>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

FeatureKind ParseFeatureKind(const std::string& text) {
  if (text == "orb") return FeatureKind::kOrb;
  if (text == "akaze") return FeatureKind::kAkaze;
  if (text == "sift") return FeatureKind::kSift;
  Fail("features must be orb, akaze or sift (SURF is not available), got '" + text + "'");
}

double KinectDepthSigmaM(double z_m) { return 0.0012 + 0.0019 * (z_m - 0.4) * (z_m - 0.4); }

void OdometryParams::Validate() const {
  if (max_features < 10) Fail("odometry.max_features must be >= 10, got " + std::to_string(max_features));
  if (!(ratio > 0 && ratio <= 1)) Fail("odometry.ratio must be in (0, 1], got " + std::to_string(ratio));
  if (!(pixel_sigma_px > 0)) Fail("odometry.pixel_sigma_px must be > 0, got " + std::to_string(pixel_sigma_px));
  ransac.Validate();
}

mapping::MatchedPoints3D MatchRgbdFeatures(const RgbdImage& a, const RgbdImage& b,
                                           const DepthIntrinsics& k, const OdometryParams& params) {
  params.Validate();
  k.Validate();
  cv::Ptr<cv::Feature2D> detector;
  int norm = cv::NORM_HAMMING;
  switch (params.features) {
    case FeatureKind::kOrb:
      detector = cv::ORB::create(params.max_features);
      break;
    case FeatureKind::kAkaze:
      detector = cv::AKAZE::create();
      break;
    case FeatureKind::kSift:
      detector = cv::SIFT::create(params.max_features);
      norm = cv::NORM_L2;
      break;
  }
  // Only pixels with depth can become 3D features.
  cv::Mat mask_a = a.depth_m > 0.f, mask_b = b.depth_m > 0.f;
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db;
  detector->detectAndCompute(a.gray, mask_a, ka, da);
  detector->detectAndCompute(b.gray, mask_b, kb, db);
  mapping::MatchedPoints3D out;
  if (da.empty() || db.empty()) {
    out.p1.resize(3, 0);
    out.p2.resize(3, 0);
    return out;
  }
  cv::BFMatcher matcher(norm);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(da, db, knn, 2);
  std::vector<Eigen::Vector3d> p1, p2;
  for (const auto& m : knn) {
    if (m.size() < 2 || m[0].distance > params.ratio * m[1].distance) continue;
    const cv::Point2f ua = ka[m[0].queryIdx].pt, ub = kb[m[0].trainIdx].pt;
    const float za = a.depth_m.at<float>(cvRound(ua.y), cvRound(ua.x));
    const float zb = b.depth_m.at<float>(cvRound(ub.y), cvRound(ub.x));
    if (!(za > 0.f) || !(zb > 0.f)) continue;
    p1.push_back(k.Unproject(ua.x, ua.y, za));
    p2.push_back(k.Unproject(ub.x, ub.y, zb));
  }
  out.p1.resize(3, static_cast<Eigen::Index>(p1.size()));
  out.p2.resize(3, static_cast<Eigen::Index>(p2.size()));
  for (std::size_t i = 0; i < p1.size(); ++i) {
    out.p1.col(i) = p1[i];
    out.p2.col(i) = p2[i];
    // Lateral sigma: the feature's pixel sigma at that depth.
    out.cov1.push_back(mapping::RayCovariance(p1[i], KinectDepthSigmaM(p1[i].z()),
                                              params.pixel_sigma_px * p1[i].z() / k.fx_px));
    out.cov2.push_back(mapping::RayCovariance(p2[i], KinectDepthSigmaM(p2[i].z()),
                                              params.pixel_sigma_px * p2[i].z() / k.fx_px));
  }
  return out;
}

std::optional<mapping::RigidMotion> EstimateEgoMotion(const RgbdImage& a, const RgbdImage& b,
                                                      const DepthIntrinsics& k,
                                                      const OdometryParams& params,
                                                      mapping::MatchedPoints3D* matches_out) {
  auto matches = MatchRgbdFeatures(a, b, k, params);
  auto motion = mapping::EstimateRigidMotion(matches, params.ransac);
  if (matches_out) *matches_out = std::move(matches);
  return motion;
}

}  // namespace romo::indoor_manip
