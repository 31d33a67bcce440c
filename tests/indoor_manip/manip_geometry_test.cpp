// Stage tests of the manipulation plugin: Kalman filter, plane projection (4.4, 4.5),
// encapsulation, hand region growing and rotation, on exact inputs or simulated RGB-D frames.
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/indoor_manip/fingerprint.hpp"
#include "romo/indoor_manip/hand_kalman.hpp"
#include "romo/indoor_manip/hand_rotation.hpp"
#include "romo/indoor_manip/hand_segmentation.hpp"
#include "romo/indoor_manip/manip_session.hpp"
#include "romo/sim_manip/sim_manip.hpp"

namespace romo::indoor_manip {
namespace {

sim_manip::SimManipScene MakeScene(const std::string& action, int frames, std::uint64_t seed = 7) {
  sim_manip::SimManipOptions o;
  o.action = action;
  o.seed = seed;
  o.frames = frames;
  return sim_manip::SimManipScene(o);
}

DepthIntrinsics IntrinsicsOf(const sim_manip::SimManipScene& s) {
  const auto& K = s.truth().K;
  return {K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
}

TEST(InteractionPlaneTest, ProjectionAndDistanceFollowEq44And45) {
  // Plane z = 1 seen from the origin: n = (0, 0, -1), d = 1 after orientation.
  const auto plane = InteractionPlane::FromCoefficients({0, 0, 2, -2});
  EXPECT_NEAR(plane.normal.z(), -1.0, 1e-12);
  EXPECT_NEAR(plane.d_m, 1.0, 1e-12);
  const Eigen::Vector3d c(0.3, -0.2, 0.8);
  EXPECT_NEAR(plane.Distance(c), 0.2, 1e-12);  // 20 cm in front of the plane
  const Eigen::Vector3d cp = plane.Project(c);
  EXPECT_NEAR((cp - Eigen::Vector3d(0.3, -0.2, 1.0)).norm(), 0.0, 1e-12);
  EXPECT_THROW(InteractionPlane::FromCoefficients({0, 0, 0, 1}), romo::Error);
  EXPECT_THROW(InteractionPlane::FromPoints({0, 0, 1}, {1, 0, 1}, {2, 0, 1}), romo::Error);
}

TEST(FingerprintTest, PcaAxesFollowTheDominantDirectionAndPlnTheCameraX) {
  const auto plane = InteractionPlane::FromCoefficients({0, 0, -1, 1});
  std::vector<double> t;
  std::vector<Eigen::Vector3d> c;
  // A stroke along the image diagonal, 5 cm above the plane.
  for (int i = 0; i < 50; ++i) {
    t.push_back(i / 30.0);
    c.emplace_back(0.004 * i, 0.004 * i, 0.95);
  }
  const Fingerprint pca = BuildFingerprint(t, c, plane, Encapsulation::kPca);
  const Fingerprint pln = BuildFingerprint(t, c, plane, Encapsulation::kPln);
  constexpr double kTolM = 1e-9;  // exact arithmetic on exact inputs
  const double diag = std::sqrt(2.0) * 0.004 * 49;
  EXPECT_NEAR(pca.box_extent_m.x(), diag, kTolM);
  EXPECT_NEAR(pca.box_extent_m.y(), 0.0, kTolM);
  EXPECT_NEAR(pln.box_extent_m.x(), 0.004 * 49, kTolM);
  EXPECT_NEAR(pln.box_extent_m.y(), 0.004 * 49, kTolM);
  for (double r : pln.profiles.r_m) EXPECT_NEAR(r, 0.05, kTolM);
}

TEST(HandKalmanTest, ConstantVelocityTargetIsTrackedWithLowProcessNoise) {
  HandKalmanParams params;
  params.accel_sigma_mps2 = 0.5;  // the target really moves at constant velocity
  HandKalmanFilter kf{params};
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.006);
  const Eigen::Vector3d v(0.3, -0.1, 0.05);  // m/s
  kf.Initialize({0, 0, 1});
  double max_err_late = 0.0;
  for (int k = 1; k <= 90; ++k) {
    const Eigen::Vector3d truth = Eigen::Vector3d(0, 0, 1) + v * (k / 30.0);
    kf.Predict(1.0 / 30.0);
    kf.Correct(truth + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    if (k > 45) max_err_late = std::max(max_err_late, (kf.position() - truth).norm());
  }
  constexpr double kMaxPosErrM = 0.012;  // 2 measurement sigmas: the filter must not amplify noise
  constexpr double kMaxVelErrMps = 0.1;  // a tenth of a typical hand speed
  EXPECT_LT(max_err_late, kMaxPosErrM);
  EXPECT_LT((kf.velocity() - v).norm(), kMaxVelErrMps);
}

TEST(HandSegmentationTest, GrowsTheHandBlobAndItsCentroidMatchesTruth) {
  const auto scene = MakeScene("poking", 2);
  const RgbdImage img = ToRgbdImage(scene.Render(0), "sim");
  const DepthIntrinsics k = IntrinsicsOf(scene);
  const auto plane = InteractionPlane::FromCoefficients(scene.truth().plane_camera);
  const HandBlob blob = GrowHandRegion(img, k, {scene.truth().seed_u_px, scene.truth().seed_v_px}, &plane, {});
  EXPECT_GT(blob.pixel_count, 150);
  // The visible shell lies up to one semi-axis (2.5-4.5 cm) in front of the ellipsoid centre.
  constexpr double kMaxCentroidErrM = 0.045;
  EXPECT_LT((blob.centroid_m - scene.truth().hand_centre_camera_m[0]).norm(), kMaxCentroidErrM);
  EXPECT_GT((blob.centroid_m - scene.truth().hand_centre_camera_m[0]).norm(), 0.0);
}

TEST(HandRotationTest, PlanarFitRecoversAKnownAngle) {
  Eigen::Matrix2Xd a(2, 40), b(2, 40);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  const Eigen::Rotation2Dd R(0.2);
  for (int i = 0; i < 40; ++i) {
    a.col(i) << u(rng), u(rng);
    b.col(i) = R * a.col(i) + Eigen::Vector2d(0.01, -0.02);
  }
  EXPECT_NEAR(FitPlanarRotation(a, b), 0.2, 1e-9);
}

TEST(HandRotationTest, TighteningTwistIsMeasuredAboutThePlaneNormal) {
  const auto scene = MakeScene("tightening", 40);
  const DepthIntrinsics k = IntrinsicsOf(scene);
  const auto plane = InteractionPlane::FromCoefficients(scene.truth().plane_camera);
  ManipAnalyzer analyzer(plane, k, ManipParams{});
  for (int i = 0; i < scene.frame_count(); ++i) {
    analyzer.AddFrame(ToRgbdImage(scene.Render(i), "sim"), {scene.truth().seed_u_px, scene.truth().seed_v_px});
  }
  const ManipResult r = analyzer.Finish();
  ASSERT_EQ(r.rotation_steps_rad.size(), 39u);
  double est = 0.0, truth = 0.0, err = 0.0;
  double est_lo = 0, est_hi = 0, truth_lo = 0, truth_hi = 0;
  for (std::size_t i = 0; i < r.rotation_steps_rad.size(); ++i) {
    const double dt = scene.truth().hand_yaw_rad[i + 1] - scene.truth().hand_yaw_rad[i];
    // The camera looks at the plane's positive side, so a twist about +n is about +Hz.
    est += r.rotation_steps_rad[i].z();
    truth += dt;
    err = std::max(err, std::abs(est - truth));
    est_lo = std::min(est_lo, est);
    est_hi = std::max(est_hi, est);
    truth_lo = std::min(truth_lo, truth);
    truth_hi = std::max(truth_hi, truth);
  }
  std::printf("twist swing: true %.1f deg, estimated %.1f deg, worst cumulative error %.1f deg\n",
              (truth_hi - truth_lo) * 180 / M_PI, (est_hi - est_lo) * 180 / M_PI, err * 180 / M_PI);
  // Flow on a 30x25 px hand underestimates the turn: measured worst cumulative error 18 deg over
  // 40 frames while the twist swings by 70-100 deg; the estimate must still show most of the swing.
  constexpr double kMaxCumulativeErrRad = 25.0 * M_PI / 180.0;
  constexpr double kMinSwingFraction = 0.5;
  EXPECT_LT(err, kMaxCumulativeErrRad);
  EXPECT_GT(est_hi - est_lo, kMinSwingFraction * (truth_hi - truth_lo));
}

TEST(ManipBadInputTest, ClearErrorsForBrokenFrames) {
  const auto scene = MakeScene("writing", 2);
  drivers::RgbdFrame f = scene.Render(0);
  drivers::RgbdFrame zero = f;
  std::fill(zero.depth.data.begin(), zero.depth.data.end(), 0);
  EXPECT_THROW(
      {
        try {
          ToRgbdImage(zero, "zero.png");
        } catch (const romo::Error& e) {
          EXPECT_NE(std::string(e.what()).find("all zero"), std::string::npos) << e.what();
          throw;
        }
      },
      romo::Error);
  drivers::RgbdFrame small = f;
  small.rgb = drivers::Image::Allocate(drivers::PixelFormat::kRgb8, 160, 120);
  EXPECT_THROW(ToRgbdImage(small, "small"), romo::Error);

  const RgbdImage img = ToRgbdImage(f, "sim");
  const DepthIntrinsics k = IntrinsicsOf(scene);
  RgbdImage holed = img;
  holed.depth_m = img.depth_m.clone();
  holed.depth_m.at<float>(10, 10) = 0.f;
  EXPECT_THROW(GrowHandRegion(holed, k, {10, 10}, nullptr, {}), romo::Error);
  EXPECT_THROW(GrowHandRegion(img, k, {-1, 10}, nullptr, {}), romo::Error);
  // A seed on the plane itself is not a hand.
  const auto plane = InteractionPlane::FromCoefficients(scene.truth().plane_camera);
  const auto [pu, pv] = scene.truth().plane_pixels[0];
  EXPECT_THROW(GrowHandRegion(img, k, {pu, pv}, &plane, {}), romo::Error);

  // No plane: a scene of scattered depth (every pixel a random depth) has no dominant plane.
  RgbdImage noisy = img;
  noisy.depth_m = cv::Mat(img.depth_m.size(), CV_32FC1);
  cv::randu(noisy.depth_m, 0.5, 3.0);
  EXPECT_THROW(ChooseInteractionPlane(noisy, k, PlaneChoice{}), romo::Error);
  EXPECT_THROW(PlaneChoice::Parse("1,2,3"), romo::Error);
  PlaneChoice picked = PlaneChoice::Parse("10,10,20,20,30,30");
  EXPECT_THROW(ChooseInteractionPlane(holed, k, picked), romo::Error);  // (10,10) has no depth
}

TEST(ManipSessionTest, PickedAndRansacPlanesAgreeWithTruth) {
  const auto scene = MakeScene("chopping", 2);
  const RgbdImage img = ToRgbdImage(scene.Render(0), "sim");
  const DepthIntrinsics k = IntrinsicsOf(scene);
  PlaneChoice picked;
  picked.automatic = false;
  for (int i = 0; i < 3; ++i) {
    picked.pixels[i] = {scene.truth().plane_pixels[i].first, scene.truth().plane_pixels[i].second};
  }
  const auto truth = InteractionPlane::FromCoefficients(scene.truth().plane_camera);
  for (const auto& choice : {PlaneChoice{}, picked}) {
    const auto p = ChooseInteractionPlane(img, k, choice);
    // Three noisy pixels at ~1.2 m (sigma ~2 mm) tilt the normal by up to ~1 deg.
    constexpr double kMaxNormalErrRad = 2.0 * M_PI / 180.0;
    constexpr double kMaxOffsetErrM = 0.01;
    EXPECT_LT(std::acos(std::min(1.0, p.normal.dot(truth.normal))), kMaxNormalErrRad);
    EXPECT_NEAR(p.d_m, truth.d_m, kMaxOffsetErrM);
  }
}

}  // namespace
}  // namespace romo::indoor_manip
