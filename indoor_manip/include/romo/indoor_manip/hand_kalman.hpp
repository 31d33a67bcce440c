#pragma once
/// 3D Kalman filter for the hand centroid: constant velocity driven by white-noise acceleration.
#include <Eigen/Core>

namespace romo::indoor_manip {

struct HandKalmanParams {
  /// Standard deviation of the white-noise acceleration (m/s^2): how abruptly hands move.
  double accel_sigma_mps2 = 8.0;
  /// Standard deviation of one centroid measurement per axis (metres).
  double measurement_sigma_m = 0.006;
  /// Prior velocity standard deviation at initialisation (m/s).
  double initial_velocity_sigma_mps = 0.5;
  /// @throws romo::Error naming the field and value.
  void Validate() const;
};

class HandKalmanFilter {
 public:
  explicit HandKalmanFilter(const HandKalmanParams& params);

  void Initialize(const Eigen::Vector3d& position_m);
  bool initialized() const { return initialized_; }
  /// Propagates by @p dt_s and returns the predicted position.
  Eigen::Vector3d Predict(double dt_s);
  /// Fuses a measured position and returns the corrected one.
  Eigen::Vector3d Correct(const Eigen::Vector3d& measured_m);
  Eigen::Vector3d position() const { return x_.head<3>(); }
  Eigen::Vector3d velocity() const { return x_.tail<3>(); }
  Eigen::Matrix3d position_covariance() const { return P_.topLeftCorner<3, 3>(); }

 private:
  HandKalmanParams params_;
  bool initialized_ = false;
  Eigen::Matrix<double, 6, 1> x_ = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> P_ = Eigen::Matrix<double, 6, 6>::Identity();
};

}  // namespace romo::indoor_manip
