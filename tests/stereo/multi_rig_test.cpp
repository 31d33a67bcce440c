#include "romo/stereo/multi_rig.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "romo/core/check.hpp"
#include "romo/stereo/synthetic.hpp"
#include "stereo_test_rigs.hpp"

namespace romo::stereo {
namespace {

constexpr int kW = 161, kH = 97;

drivers::Image ToImage(const cv::Mat& m) {
  drivers::Image img = drivers::Image::Allocate(drivers::PixelFormat::kMono8, m.cols, m.rows);
  for (int y = 0; y < m.rows; ++y) std::memcpy(img.row(y), m.ptr(y), static_cast<std::size_t>(m.cols));
  return img;
}

drivers::Calibration ThreeRigs() {
  drivers::Calibration c;
  for (int id : {0, 1, 2}) c.rigs.push_back(testing::MakeRig(id, kW, kH, /*distortion=*/false));
  return c;
}

drivers::StereoFrame Frame(int rig_id, double distance_m) {
  RectifiedGeometry g;
  g.focal_px = 400.0;
  g.baseline_m = 0.25;
  g.cx_px = (kW - 1) / 2.0;
  g.cy_px = (kH - 1) / 2.0;
  const SyntheticPair pair = RenderPlanePair(g, kW, kH, Eigen::Vector3d(0, 0, 1), distance_m, 20 + rig_id);
  drivers::StereoFrame f;
  f.rig_id = rig_id;
  f.left.image = ToImage(pair.left);
  f.right.image = ToImage(pair.right);
  return f;
}

StereoParams Params() {
  StereoParams p;
  p.disparity_size = 32;
  return p;
}

TEST(MultiRigTest, ParallelResultsEqualSequentialAndLandInVehicleFrame) {
  const drivers::Calibration calib = ThreeRigs();
  MultiRigStereo stereo(calib, Params(), 3);
  EXPECT_EQ(stereo.threads(), 3);
  drivers::FrameSet set;
  const double distances[] = {4.0, 5.0, 6.0};
  for (int id : {0, 1, 2}) set.stereo.push_back(Frame(id, distances[id]));
  const std::vector<RigResult> parallel = stereo.Process(set);
  ASSERT_EQ(parallel.size(), 3u);
  for (int id : {0, 1, 2}) {
    const RigResult& r = parallel[static_cast<std::size_t>(id)];
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(r.rig_id, id);
    const RigResult sequential = stereo.ProcessRig(set.stereo[static_cast<std::size_t>(id)]);
    EXPECT_EQ(cv::norm(r.disparity, sequential.disparity, cv::NORM_INF), 0.0);
    ASSERT_EQ(r.cloud_vehicle.size(), sequential.cloud_vehicle.size());
    EXPECT_TRUE(r.cloud_vehicle.xyz.isApprox(sequential.cloud_vehicle.xyz));
    // Back into the rig frame: the plane's depth, within the mean sigma_z (eq. 2.3).
    PointCloud rig_frame = r.cloud_vehicle;
    rig_frame.Transform(calib.rigs[static_cast<std::size_t>(id)].T_vehicle_rig.inverse().cast<float>());
    ASSERT_GT(rig_frame.size(), static_cast<std::size_t>(kW * kH / 2));
    double err = 0.0, sigma = 0.0;
    for (std::size_t i = 0; i < rig_frame.size(); ++i) {
      err += std::abs(rig_frame.xyz(2, static_cast<Eigen::Index>(i)) - distances[id]);
      sigma += rig_frame.sigma_z_m[i];
    }
    EXPECT_LE(err / rig_frame.size(), sigma / rig_frame.size()) << "rig " << id;
    EXPECT_GT(r.total_ms, 0.0);
  }
}

TEST(MultiRigTest, BadRigFailsAloneWithReason) {
  MultiRigStereo stereo(ThreeRigs(), Params(), 2);
  drivers::FrameSet set;
  set.stereo.push_back(Frame(0, 5.0));
  set.stereo.push_back(Frame(9, 5.0));  // no such rig
  drivers::StereoFrame flat = Frame(1, 5.0);
  std::fill(flat.left.image.data.begin(), flat.left.image.data.end(), 77);
  set.stereo.push_back(flat);
  drivers::StereoFrame small = Frame(2, 5.0);
  small.left.image = drivers::Image::Allocate(drivers::PixelFormat::kMono8, kW - 1, kH);
  small.right.image = small.left.image;
  set.stereo.push_back(small);
  const std::vector<RigResult> r = stereo.Process(set);
  ASSERT_EQ(r.size(), 4u);
  EXPECT_TRUE(r[0].ok) << r[0].error;
  EXPECT_FALSE(r[1].ok);
  EXPECT_NE(r[1].error.find("rig 9"), std::string::npos) << r[1].error;
  EXPECT_FALSE(r[2].ok);
  EXPECT_NE(r[2].error.find("constant"), std::string::npos) << r[2].error;
  EXPECT_FALSE(r[3].ok);
  EXPECT_NE(r[3].error.find("160x97"), std::string::npos) << r[3].error;
}

TEST(MultiRigTest, RejectsBadParametersAndCalibration) {
  StereoParams p = Params();
  p.disparity_size = 40;
  EXPECT_THROW(MultiRigStereo(ThreeRigs(), p), Error);
  drivers::Calibration bad = ThreeRigs();
  bad.rigs[1].T = Eigen::Vector3d(0, 0.25, 0);
  EXPECT_THROW(MultiRigStereo(bad, Params()), Error);
  EXPECT_THROW(MultiRigStereo(drivers::Calibration{}, Params()), Error);
}

}  // namespace
}  // namespace romo::stereo
