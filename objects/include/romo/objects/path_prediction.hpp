#pragma once
/// Pedestrian path prediction in the ground plane (dissertation 4.3.4): a recursive least squares
/// (RLS) straight-line fit of the xy trail with a forgetting factor, updated at every new position,
/// and the constant-velocity (CV) baseline. Both predict positions with a 2x2 covariance each.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace romo::objects {

/// One predicted position of a path.
struct PredictedPoint {
  double dt_s = 0.0;  ///< time after the last observation
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov_m2 = Eigen::Matrix2d::Zero();  ///< position covariance (m^2)
};

enum class PredictorKind { kRls, kConstantVelocity };

/// "rls" or "cv".
const char* ToString(PredictorKind kind);
/// Parses "rls" / "cv"; @throws romo::Error naming the value otherwise.
PredictorKind ParsePredictorKind(const std::string& text);

struct PredictorParams {
  PredictorKind kind = PredictorKind::kRls;
  /// RLS forgetting factor lambda in (0, 1]: the weight of an observation k steps old is
  /// lambda^k. 0.6 was the best on ETH/UCY hotel (tuned over 0.2..1.0, see README): ~2.5
  /// steps (1 s at 2.5 Hz) of memory averages the annotation jitter of the positions and
  /// still follows a slowly turning walker.
  double forgetting = 0.6;
  /// Noise-adaptive forgetting (RLS only): when the recent trail is not dominated by position
  /// noise, the line fit's memory only lags a walker who changes speed, so the predictor uses
  /// the lambda -> 0 limit of the fit (the latest step's velocity). Test: lag-1 correlation of
  /// consecutive second differences over the last noise_window positions; white position noise
  /// gives -2/3, a smooth change of velocity gives > 0. The fit is used below the threshold.
  bool adaptive = true;
  int noise_window = 8;
  double noise_correlation_threshold = -0.2;
  /// Prediction horizon (dissertation default 4.8 s = 12 steps at 2.5 Hz).
  double horizon_s = 4.8;
  /// Spacing of the predicted points; 0 = the mean spacing of the observations.
  double step_s = 0.0;
  /// Floor on the per-axis position standard deviation of the residual model (m).
  double min_sigma_m = 0.05;
  /// @throws romo::Error naming the field and value when out of range.
  void Validate() const;
};

/// A predictor of one pedestrian's path. Feed positions in time order with Update().
class PathPredictor {
 public:
  virtual ~PathPredictor() = default;
  /// Adds the position observed at @p t_s (strictly increasing).
  /// @throws romo::Error when @p t_s does not increase or the position is not finite.
  virtual void Update(double t_s, const Eigen::Vector2d& xy_m) = 0;
  /// @p steps positions spaced @p step_s after the last observation. Empty before any Update().
  virtual std::vector<PredictedPoint> Predict(int steps, double step_s) const = 0;
  /// Predicts over params().horizon_s with params().step_s (or the observed mean spacing).
  std::vector<PredictedPoint> PredictHorizon() const;
  /// Current velocity estimate (m/s); zero before two observations.
  virtual Eigen::Vector2d velocity_mps() const = 0;
  virtual int observations() const = 0;
  virtual double last_time_s() const = 0;
  /// Mean spacing of the observations so far (s); 0 before two.
  virtual double mean_step_s() const = 0;
  const PredictorParams& params() const { return params_; }

 protected:
  explicit PathPredictor(const PredictorParams& params);
  PredictorParams params_;
};

/// RLS line fit: per axis, position = a + b * (t - t_last) with parameters re-expressed at each
/// new time (a constant-velocity transition), weighted least squares with exponential
/// forgetting; the covariance of a predicted point is the weighted residual covariance times
/// (1 + phi' P phi), phi = (1, dt).
class RlsPathPredictor final : public PathPredictor {
 public:
  explicit RlsPathPredictor(const PredictorParams& params);
  void Update(double t_s, const Eigen::Vector2d& xy_m) override;
  std::vector<PredictedPoint> Predict(int steps, double step_s) const override;
  Eigen::Vector2d velocity_mps() const override;
  int observations() const override { return n_; }
  double last_time_s() const override { return t_last_; }
  double mean_step_s() const override;

 private:
  int n_ = 0;
  double t_first_ = 0.0;
  double t_last_ = 0.0;
  Eigen::Matrix2d theta_ = Eigen::Matrix2d::Zero();  ///< columns x, y; rows position, velocity
  Eigen::Matrix2d P_ = Eigen::Matrix2d::Identity();  ///< inverse weighted information
  Eigen::Matrix2d residual_sum_ = Eigen::Matrix2d::Zero();  ///< forgetting-weighted e e'
  double weight_sum_ = 0.0;
  std::vector<Eigen::Vector2d> recent_;  ///< ring of the last noise_window positions
  std::vector<double> recent_t_;
  int recent_next_ = 0;

 public:
  /// True when the last Predict() would use the line fit (noise-dominated trail or not adaptive).
  bool UsesLineFit() const;
  /// Lag-1 correlation of second differences of the recent trail (0 with fewer than 4 points).
  double SecondDifferenceCorrelation() const;
};

/// Constant velocity from the last step (the usual ETH/UCY baseline); the covariance grows with
/// the last step's velocity uncertainty (two position errors of min_sigma_m).
class ConstantVelocityPredictor final : public PathPredictor {
 public:
  explicit ConstantVelocityPredictor(const PredictorParams& params);
  void Update(double t_s, const Eigen::Vector2d& xy_m) override;
  std::vector<PredictedPoint> Predict(int steps, double step_s) const override;
  Eigen::Vector2d velocity_mps() const override { return v_; }
  int observations() const override { return n_; }
  double last_time_s() const override { return t_last_; }
  double mean_step_s() const override;

 private:
  int n_ = 0;
  double t_first_ = 0.0;
  double t_last_ = 0.0;
  double last_dt_ = 0.0;
  Eigen::Vector2d last_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d v_ = Eigen::Vector2d::Zero();
};

/// The predictor selected by @p params.kind. @throws romo::Error when params are invalid.
std::unique_ptr<PathPredictor> MakePathPredictor(const PredictorParams& params);

}  // namespace romo::objects
