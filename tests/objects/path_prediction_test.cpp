// RLS and constant-velocity path predictors on synthetic walks with known answers.
#include <random>

#include <Eigen/LU>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/objects/path_prediction.hpp"

namespace romo::objects {
namespace {

// Noise-free straight walks must be extrapolated exactly up to double round-off.
constexpr double kExactM = 1e-6;

TEST(PathPredictionTest, RlsExtrapolatesStraightWalkExactly) {
  PredictorParams params;
  RlsPathPredictor rls(params);
  const Eigen::Vector2d start(1.0, -2.0), velocity(1.2, 0.5);
  for (int k = 0; k < 10; ++k) rls.Update(0.1 * k, start + velocity * 0.1 * k);
  const auto path = rls.Predict(48, 0.1);
  ASSERT_EQ(path.size(), 48u);
  for (std::size_t k = 0; k < path.size(); ++k) {
    const Eigen::Vector2d truth = start + velocity * (0.9 + path[k].dt_s);
    EXPECT_LT((path[k].xy_m - truth).norm(), kExactM) << "step " << k;
  }
  EXPECT_LT((rls.velocity_mps() - velocity).norm(), kExactM);
}

TEST(PathPredictionTest, HorizonDefaultsToFourPointEightSecondsAtFrameRate) {
  PredictorParams params;  // horizon 4.8 s, step from the observations
  for (auto kind : {PredictorKind::kRls, PredictorKind::kConstantVelocity}) {
    params.kind = kind;
    auto p = MakePathPredictor(params);
    for (int k = 0; k < 5; ++k) p->Update(0.1 * k, Eigen::Vector2d(0.1 * k, 0.0));
    const auto path = p->PredictHorizon();
    ASSERT_EQ(path.size(), 48u) << ToString(kind);  // 4.8 s at 10 Hz
    EXPECT_NEAR(path.back().dt_s, 4.8, 1e-9);
  }
}

TEST(PathPredictionTest, RlsAveragesPositionNoiseBetterThanConstantVelocity) {
  // Straight walk at 1.3 m/s with 8 cm position noise (annotation-like jitter): the line fit's
  // memory averages the noise, the last-step velocity amplifies it.
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.08);
  PredictorParams params;
  params.adaptive = false;
  double rls_error = 0.0, cv_error = 0.0;
  const Eigen::Vector2d velocity(1.3, 0.0);
  for (int trial = 0; trial < 200; ++trial) {
    RlsPathPredictor rls(params);
    ConstantVelocityPredictor cv(params);
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector2d p = velocity * 0.4 * k + Eigen::Vector2d(noise(rng), noise(rng));
      rls.Update(0.4 * k, p);
      cv.Update(0.4 * k, p);
    }
    const Eigen::Vector2d truth = velocity * 0.4 * 19;
    rls_error += (rls.Predict(12, 0.4).back().xy_m - truth).norm();
    cv_error += (cv.Predict(12, 0.4).back().xy_m - truth).norm();
  }
  EXPECT_LT(rls_error, 0.6 * cv_error);
}

TEST(PathPredictionTest, CovarianceGrowsWithHorizonAndResidual) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1);
  PredictorParams params;
  params.adaptive = false;
  RlsPathPredictor rls(params);
  for (int k = 0; k < 20; ++k) {
    rls.Update(0.1 * k, Eigen::Vector2d(0.1 * k + noise(rng), noise(rng)));
  }
  const auto path = rls.Predict(48, 0.1);
  for (std::size_t k = 1; k < path.size(); ++k) {
    EXPECT_GT(path[k].cov_m2.trace(), path[k - 1].cov_m2.trace());
    EXPECT_GT(path[k].cov_m2.determinant(), 0.0);  // positive definite
  }
  // The first step's spread is at least the floor and near the measured 0.1 m noise.
  EXPECT_GT(std::sqrt(path[0].cov_m2(0, 0)), params.min_sigma_m);
  EXPECT_LT(std::sqrt(path[0].cov_m2(0, 0)), 0.5);
}

TEST(PathPredictionTest, AdaptiveFollowsSmoothSpeedChangeLikeConstantVelocity) {
  // Noise-free walker speeding up: second differences are all alike (the lag-1 correlation
  // over m = 8 positions is then (m - 3) / (m - 2) = 5/6), so the adaptive predictor uses the
  // latest step, as CV does.
  PredictorParams params;
  RlsPathPredictor rls(params);
  ConstantVelocityPredictor cv(params);
  for (int k = 0; k < 8; ++k) {
    const double t = 0.4 * k;
    const Eigen::Vector2d p(0.5 * t + 0.1 * t * t, 0.0);
    rls.Update(t, p);
    cv.Update(t, p);
  }
  EXPECT_FALSE(rls.UsesLineFit());
  EXPECT_NEAR(rls.SecondDifferenceCorrelation(), 5.0 / 6.0, 1e-9);
  EXPECT_LT((rls.Predict(12, 0.4).back().xy_m - cv.Predict(12, 0.4).back().xy_m).norm(), kExactM);
}

TEST(PathPredictionTest, RejectsBadInput) {
  PredictorParams params;
  params.forgetting = 1.5;
  EXPECT_THROW(params.Validate(), romo::Error);
  RlsPathPredictor rls(PredictorParams{});
  rls.Update(1.0, Eigen::Vector2d(0, 0));
  EXPECT_THROW(rls.Update(1.0, Eigen::Vector2d(1, 0)), romo::Error);  // time does not increase
  EXPECT_THROW(rls.Update(2.0, Eigen::Vector2d(std::nan(""), 0)), romo::Error);
  EXPECT_THROW(ParsePredictorKind("kalman"), romo::Error);
}

}  // namespace
}  // namespace romo::objects
