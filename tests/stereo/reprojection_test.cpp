#include "romo/stereo/reprojection.hpp"

#include <cmath>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "romo/core/check.hpp"
#include "romo/stereo/sgm.hpp"
#include "romo/stereo/synthetic.hpp"
#include "stereo_test_rigs.hpp"

namespace romo::stereo {
namespace {

RectifiedGeometry Geometry(int width, int height) {
  RectifiedGeometry g;
  g.focal_px = 400.0;
  g.baseline_m = 0.25;
  g.cx_px = (width - 1) / 2.0;
  g.cy_px = (height - 1) / 2.0;
  return g;
}

// Matches a rendered plane with romo's defaults and checks every reprojected point against the
// analytic plane along its own viewing ray: the mean depth error must lie within the mean
// sigma_z that eq. 2.3 predicts (sigma_d = 0.25 px).
void ExpectPlaneWithinSigma(const Eigen::Vector3d& normal, double distance_m) {
  constexpr int kW = 321, kH = 241;  // odd on purpose
  const RectifiedGeometry g = Geometry(kW, kH);
  const SyntheticPair pair = RenderPlanePair(g, kW, kH, normal, distance_m, 5);
  StereoSgm sgm(kW, kH, 48, 8, 16);
  cv::Mat d;
  sgm.execute(pair.left, pair.right, &d);
  const PointCloud cloud = ReprojectDisparity(d, sgm.subpixel_scale(), sgm.get_invalid_disparity(), pair.left, g,
                                              ReprojectionParams{});
  ASSERT_GT(cloud.size(), static_cast<std::size_t>(kW * kH / 2));
  const Eigen::Vector3d n = normal.normalized();
  double sum_abs_err = 0.0, sum_sigma = 0.0;
  for (Eigen::Index i = 0; i < cloud.xyz.cols(); ++i) {
    const Eigen::Vector3d p = cloud.xyz.col(i).cast<double>();
    const Eigen::Vector3d ray = p / p.z();
    const double z_true = distance_m / n.dot(ray);
    sum_abs_err += std::abs(p.z() - z_true);
    sum_sigma += cloud.sigma_z_m[static_cast<std::size_t>(i)];
  }
  const double mean_err = sum_abs_err / cloud.size(), mean_sigma = sum_sigma / cloud.size();
  std::printf("plane n=(%.2f %.2f %.2f) c=%.1f m: %zu points, mean |dz| %.4f m, mean sigma_z %.4f m\n", n.x(), n.y(),
              n.z(), distance_m, cloud.size(), mean_err, mean_sigma);
  EXPECT_LE(mean_err, mean_sigma);
}

TEST(ReprojectionTest, FrontoParallelPlaneWithinSigmaZ) { ExpectPlaneWithinSigma({0, 0, 1}, 6.0); }

TEST(ReprojectionTest, TiltedPlaneWithinSigmaZ) { ExpectPlaneWithinSigma({0.5, 0.2, 0.84}, 5.0); }

// A box 2 m away in front of a wall 4 m away, its outline smeared by the matcher over two
// columns (intermediate disparities that would float between the two), and a floor slanting
// away: with max_disparity_spread the smeared columns and the pixels beside them go, the box,
// the wall and the slanted floor stay.
TEST(ReprojectionTest, OutlinePixelsBetweenNearAndFarAreDropped) {
  constexpr int kW = 60, kH = 40, kScale = 16;
  const RectifiedGeometry g = Geometry(kW, kH);
  const double bf = g.focal_px * g.baseline_m;  // 100 px m
  cv::Mat d(kH, kW, CV_16SC1);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      double disparity = bf / 4.0;                     // wall, 25 px
      if (u >= 20 && u < 40) disparity = bf / 2.0;     // box, 50 px
      if (u == 18 || u == 41) disparity = bf / 3.2;    // smeared outline, 31.25 px
      if (u == 19 || u == 40) disparity = bf / 2.6;    // 38.5 px
      if (v >= 30) disparity = 20.0 + 0.5 * (v - 30);  // floor: 0.5 px a row (2.5 % a pixel)
      d.at<short>(v, u) = static_cast<short>(std::lround(disparity * kScale));
    }
  }
  ReprojectionParams params;
  const PointCloud all = ReprojectDisparity(d, kScale, -1, cv::Mat(), g, params);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(kW * kH));
  params.max_disparity_spread = 0.05;
  params.min_outline_step_px = 0.0;
  const PointCloud kept = ReprojectDisparity(d, kScale, -1, cv::Mat(), g, params);
  int floating = 0, box = 0, floor = 0;
  for (Eigen::Index i = 0; i < kept.xyz.cols(); ++i) {
    const double z = kept.xyz(2, i);
    const long row = std::lround(kept.xyz(1, i) * g.focal_px / z + g.cy_px);
    if (row >= 30) {
      ++floor;
    } else if (std::abs(z - 2.0) < 1e-3) {
      ++box;
    } else if (std::abs(z - 4.0) > 1e-3) {
      ++floating;  // neither box nor wall
    }
  }
  EXPECT_EQ(floating, 0);
  // The box's 20 columns less the outermost one on each side (next to the smear), rows 0-28
  // (row 29 touches the floor's row 30).
  EXPECT_EQ(box, 18 * 29);
  // The slanting floor (0.5 px a row, under 5 % of its disparity) keeps every row but the one
  // next to the box and wall above it.
  EXPECT_EQ(floor, kW * 9);
  // Off by default.
  EXPECT_EQ(ReprojectionParams{}.max_disparity_spread, 0.0);
}

// Against OpenCV's reprojectImageTo3D with the rectifier's Q (the reference) on an odd size.
TEST(ReprojectionTest, MatchesOpenCvReprojectImageTo3D) {
  const Rectifier rect(testing::MakeRig(0, 161, 97));
  cv::Mat d(97, 161, CV_16SC1);
  cv::RNG rng(2);
  rng.fill(d, cv::RNG::UNIFORM, 32, 960);
  for (int i = 0; i < 500; ++i) d.at<short>(rng.uniform(0, 97), rng.uniform(0, 161)) = -16;
  ReprojectionParams params;
  params.max_range_m = 1e6;  // keep everything
  const PointCloud cloud = ReprojectDisparity(d, 16, -16, cv::Mat(), rect.geometry(), params);
  cv::Mat df, xyz;
  d.convertTo(df, CV_32F, 1.0 / 16);
  cv::reprojectImageTo3D(df, xyz, rect.Q());
  // float arithmetic on metre-scale coordinates: 1e-4 relative.
  constexpr double kRelTol = 1e-4;
  Eigen::Index k = 0;
  for (int y = 0; y < d.rows; ++y) {
    for (int x = 0; x < d.cols; ++x) {
      if (d.at<short>(y, x) == -16) continue;
      const cv::Vec3f r = xyz.at<cv::Vec3f>(y, x);
      const Eigen::Vector3d expected = rect.geometry().R_rig_rect * Eigen::Vector3d(r[0], r[1], r[2]);
      ASSERT_LT(k, cloud.xyz.cols());
      ASSERT_LE((cloud.xyz.col(k).cast<double>() - expected).norm(), kRelTol * expected.norm()) << x << "," << y;
      ++k;
    }
  }
  EXPECT_EQ(k, cloud.xyz.cols());
}

TEST(ReprojectionTest, SigmaZRangeLimitAndVehicleFrame) {
  cv::Mat d(3, 5, CV_16SC1, cv::Scalar(-16));
  const RectifiedGeometry g = Geometry(5, 3);  // cx = 2, cy = 1
  d.at<short>(1, 2) = 10 * 16;  // 10 px at the principal point: Z = 0.25 * 400 / 10 = 10 m
  ReprojectionParams params;
  params.sigma_d_px = 0.5;
  const drivers::RigCalibration rig = testing::MakeRig(0, 5, 3);
  const PointCloud cloud = ReprojectDisparity(d, 16, -16, cv::Mat(), g, params, rig.T_vehicle_rig);
  ASSERT_EQ(cloud.size(), 1u);
  // Eq. 2.3: sigma_z = Z^2 / (b f) * sigma_d = 100 / 100 * 0.5.
  constexpr float kTolM = 1e-5f;
  EXPECT_NEAR(cloud.sigma_z_m[0], 0.5f, kTolM);
  // 10 m along the optical axis, pitched down 15 deg from (1.4, 0, 1.2).
  const double pitch = 15.0 * M_PI / 180.0;
  EXPECT_NEAR(cloud.xyz(0, 0), 1.4 + 10.0 * std::cos(pitch), 1e-4);
  EXPECT_NEAR(cloud.xyz(1, 0), 0.0, 1e-4);
  EXPECT_NEAR(cloud.xyz(2, 0), 1.2 - 10.0 * std::sin(pitch), 1e-4);
  params.max_range_m = 9.0;
  EXPECT_TRUE(ReprojectDisparity(d, 16, -16, cv::Mat(), g, params).empty());
}

TEST(ReprojectionTest, RejectsBadInput) {
  const RectifiedGeometry g = Geometry(5, 3);
  EXPECT_THROW(ReprojectDisparity(cv::Mat(3, 5, CV_32FC1), 16, -16, cv::Mat(), g, {}), Error);
  EXPECT_THROW(ReprojectDisparity(cv::Mat(3, 5, CV_16SC1), 16, -16, cv::Mat(4, 5, CV_8UC1), g, {}), Error);
  ReprojectionParams bad;
  bad.max_range_m = 0.0;
  EXPECT_THROW(ReprojectDisparity(cv::Mat(3, 5, CV_16SC1), 16, -16, cv::Mat(), g, bad), Error);
  ReprojectionParams negative_spread;
  negative_spread.max_disparity_spread = -0.1;
  EXPECT_THROW(ReprojectDisparity(cv::Mat(3, 5, CV_16SC1), 16, -16, cv::Mat(), g, negative_spread), Error);
  RectifiedGeometry no_baseline = g;
  no_baseline.baseline_m = 0.0;
  EXPECT_THROW(ReprojectDisparity(cv::Mat(3, 5, CV_16SC1), 16, -16, cv::Mat(), no_baseline, {}), Error);
}

}  // namespace
}  // namespace romo::stereo
