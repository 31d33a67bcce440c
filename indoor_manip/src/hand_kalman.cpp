#include "romo/indoor_manip/hand_kalman.hpp"

#include <Eigen/Dense>

#include <string>

#include "romo/core/check.hpp"

namespace romo::indoor_manip {

void HandKalmanParams::Validate() const {
  if (!(accel_sigma_mps2 > 0.0)) Fail("kalman.accel_sigma_mps2 must be > 0, got " + std::to_string(accel_sigma_mps2));
  if (!(measurement_sigma_m > 0.0)) Fail("kalman.measurement_sigma_m must be > 0, got " + std::to_string(measurement_sigma_m));
  if (!(initial_velocity_sigma_mps > 0.0)) {
    Fail("kalman.initial_velocity_sigma_mps must be > 0, got " + std::to_string(initial_velocity_sigma_mps));
  }
}

HandKalmanFilter::HandKalmanFilter(const HandKalmanParams& params) : params_(params) {
  params_.Validate();
}

void HandKalmanFilter::Initialize(const Eigen::Vector3d& position_m) {
  x_.setZero();
  x_.head<3>() = position_m;
  P_.setZero();
  const double sm = params_.measurement_sigma_m;
  const double sv = params_.initial_velocity_sigma_mps;
  P_.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * sm * sm;
  P_.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * sv * sv;
  initialized_ = true;
}

Eigen::Vector3d HandKalmanFilter::Predict(double dt_s) {
  ROMO_THROW_UNLESS(initialized_ && dt_s >= 0.0);
  Eigen::Matrix<double, 6, 6> F = Eigen::Matrix<double, 6, 6>::Identity();
  F.topRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * dt_s;
  // Discrete white-noise acceleration: a constant acceleration per step of variance q.
  const double q = params_.accel_sigma_mps2 * params_.accel_sigma_mps2;
  const double dt2 = dt_s * dt_s;
  Eigen::Matrix<double, 6, 6> Q = Eigen::Matrix<double, 6, 6>::Zero();
  Q.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * (q * dt2 * dt2 / 4.0);
  Q.topRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * (q * dt2 * dt_s / 2.0);
  Q.bottomLeftCorner<3, 3>() = Q.topRightCorner<3, 3>();
  Q.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * (q * dt2);
  x_ = F * x_;
  P_ = F * P_ * F.transpose() + Q;
  return position();
}

Eigen::Vector3d HandKalmanFilter::Correct(const Eigen::Vector3d& measured_m) {
  ROMO_THROW_UNLESS(initialized_);
  const double r = params_.measurement_sigma_m * params_.measurement_sigma_m;
  const Eigen::Matrix3d S = P_.topLeftCorner<3, 3>() + Eigen::Matrix3d::Identity() * r;
  const Eigen::Matrix<double, 6, 3> K = P_.leftCols<3>() * S.inverse();
  x_ += K * (measured_m - x_.head<3>());
  Eigen::Matrix<double, 6, 6> I_KH = Eigen::Matrix<double, 6, 6>::Identity();
  I_KH.leftCols<3>() -= K;
  // Joseph form keeps P symmetric positive definite over long runs.
  P_ = I_KH * P_ * I_KH.transpose() + K * r * K.transpose();
  return position();
}

}  // namespace romo::indoor_manip
